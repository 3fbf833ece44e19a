"""The exceptions of the appell package."""

from __future__ import annotations

from dataclasses import dataclass
from typing import List, Optional


class AppellError(Exception):
    """Base class of every error this package raises on purpose."""


class ModelError(AppellError, ValueError):
    """A model could not be evaluated where it was asked to be: a singular
    configuration, a parameter that must be positive, a non-finite input or
    result. The message is the Rust runtime's, prefixed with the function
    and, in a batch, the row."""


class ToolchainError(AppellError, RuntimeError):
    """No Rust toolchain: compiling a model needs ``cargo`` (see
    https://rustup.rs), as PyDy's Cython generator needs a C compiler."""


@dataclass(frozen=True)
class Diagnostic:
    """One error of the derive or of rustc, placed in the model text."""

    message: str
    """The compiler's message (the derive's own words)."""
    line: Optional[int]
    """1-based line in the model text, or None when the error is elsewhere."""
    column: Optional[int]
    """1-based column in that line."""
    source_line: Optional[str]
    """The offending line of the model text."""

    def __str__(self) -> str:
        if self.line is None:
            return self.message
        text = f"line {self.line}: {self.message}"
        if self.source_line is not None:
            caret = " " * max((self.column or 1) - 1, 0) + "^"
            text += f"\n    {self.source_line}\n    {caret}"
        return text


class CompileError(AppellError):
    """The model did not compile. ``diagnostics`` holds each error with the
    line of the model text it points at; ``log`` the compiler's output."""

    def __init__(self, message: str, diagnostics: List[Diagnostic], log: str = ""):
        super().__init__(message)
        self.diagnostics = diagnostics
        self.log = log
