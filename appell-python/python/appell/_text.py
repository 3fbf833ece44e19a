"""The model text of ``appell.from_model`` as the Rust crate that compiles it.

The text is the content of the ``#[appell(...)]`` attributes, in the Rust
model language (docs/model-language.md). Either write the items one after
another (a line break between two items is as good as a comma), or paste
the attributes themselves (``#[appell(...)]`` lines, as in a Rust file).
Line numbers are kept, so an error of the derive points at the text's line.
"""

from __future__ import annotations

import keyword
import re
from typing import List, Sequence, Tuple

_IDENT = re.compile(r"^[A-Za-z_][A-Za-z0-9_]*$")
_RUST_KEYWORDS = {
    "as", "break", "const", "continue", "crate", "else", "enum", "extern", "false", "fn",
    "for", "if", "impl", "in", "let", "loop", "match", "mod", "move", "mut", "pub", "ref",
    "return", "self", "Self", "static", "struct", "super", "trait", "true", "type", "unsafe",
    "use", "where", "while", "async", "await", "dyn", "abstract", "become", "box", "do",
    "final", "macro", "override", "priv", "typeof", "unsized", "virtual", "yield", "try",
}


def check_identifier(kind: str, name: str) -> None:
    """Raises ValueError unless ``name`` can name a Rust struct or field."""
    if not isinstance(name, str) or not _IDENT.match(name) or name in _RUST_KEYWORDS or name == "_":
        raise ValueError(f"{kind} {name!r} is not a valid identifier for the model")


def _is_attribute_text(source: str) -> bool:
    for line in source.splitlines():
        stripped = line.strip()
        if not stripped or stripped.startswith("//"):
            continue
        return stripped.startswith("#[")
    return False


def _items_with_commas(source: str) -> str:
    """Adds a comma after each top-level item that ends a line without one,
    so that items may be written one per line. Strings and ``//`` comments
    are skipped; line numbers are unchanged."""
    out: List[str] = []
    depth = 0
    i = 0
    n = len(source)
    last_significant = -1  # index in `out` of the line's last code character
    while i < n:
        c = source[i]
        if c == '"':
            j = i + 1
            while j < n and source[j] != '"':
                j += 2 if source[j] == "\\" else 1
            out.append(source[i : j + 1])
            last_significant = len(out) - 1
            i = j + 1
            continue
        if c == "/" and i + 1 < n and source[i + 1] == "/":
            j = source.find("\n", i)
            j = n if j < 0 else j
            out.append(source[i:j])
            i = j
            continue
        if c == "\n":
            if depth == 0 and last_significant >= 0 and not out[last_significant].endswith(","):
                out[last_significant] += ","
            last_significant = -1
            out.append(c)
            i += 1
            continue
        if c in "([{":
            depth += 1
        elif c in ")]}":
            depth -= 1
        out.append(c)
        if not c.isspace():
            last_significant = len(out) - 1
        i += 1
    return "".join(out)


def crate_source(
    name: str, source: str, parameters: Sequence[str], module: str
) -> Tuple[str, int]:
    """The crate's ``lib.rs`` and the line of it that holds the model text's
    first line."""
    check_identifier("model name", name)
    for p in parameters:
        check_identifier("parameter", p)
        if keyword.iskeyword(p):
            raise ValueError(f"parameter {p!r} is a Python keyword; name it otherwise")
    if len(set(parameters)) != len(parameters):
        raise ValueError(f"parameters named twice: {list(parameters)}")
    head = [
        "// Written by the appell Python package; the model text starts below.",
        "#![allow(clippy::all, unused)]",
        "use appell::Appell;",
        "#[derive(Appell, Clone, Default)]",
    ]
    if _is_attribute_text(source):
        first = len(head) + 1
        body = source
    else:
        head.append("#[appell(")
        first = len(head) + 1
        body = _items_with_commas(source)
    fields = "".join(f"    pub {p}: f64,\n" for p in parameters)
    tail = (
        f"\npub struct {name} {{\n{fields}}}\n\n"
        "#[pyo3::pymodule]\n"
        f"fn {module}(m: &pyo3::Bound<'_, pyo3::types::PyModule>) -> pyo3::PyResult<()> {{\n"
        f"    appell_python_glue::register::<{name}>(m)\n"
        "}\n"
    )
    closing = "" if _is_attribute_text(source) else "\n)]"
    text = "\n".join(head) + "\n" + body + closing + tail
    return text, first
