"""Write a parsed template back as TOML text: the package's writer (tests and benchmarks change a shipped
template's values and write it back)."""

from __future__ import annotations

from fabricate.tomlwrite import dumps as toml_text

__all__ = ["toml_text"]
