//! Fixed-step integration.
