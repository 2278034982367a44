"""Template bytes: a UTF-8 byte-order mark is accepted; Latin-1, binary, oversized or absurdly nested files
are refused with exit 2 naming the file, never a traceback."""

from __future__ import annotations

from pathlib import Path

import pytest

from fabricate.cli import main
from fabricate.design import load_design
from fabricate.templates import MAX_TEMPLATE_BYTES, TEMPLATE_DIR

SOURCE = TEMPLATE_DIR / "gear_pair_elliptic.toml"


def test_a_byte_order_mark_is_accepted(tmp_path):
    path = tmp_path / "bom.toml"
    path.write_bytes(b"\xef\xbb\xbf" + SOURCE.read_bytes())
    design = load_design(path)
    plain = load_design(SOURCE)
    assert design.name == plain.name and design.gears == plain.gears and design.method == plain.method
    assert not design.template_text.startswith("\ufeff")


def _bad(tmp_path: Path, data: bytes) -> Path:
    path = tmp_path / "bad.toml"
    path.write_bytes(data)
    return path


@pytest.mark.parametrize(("data", "needle"), [
    ("[design]\nname = 'caf\u00e9'\nkind = 'gear_pair'\n".encode("latin-1"), "not UTF-8 text (byte 20"),
    (bytes(range(256)) * 4, "not UTF-8 text"),
    (b"\x89PNG\r\n\x1a\n" + b"\0" * 100, "not UTF-8 text"),
    (b"x = " + b"[" * 5000 + b"]" * 5000 + b"\n", "invalid TOML"),
    (b"# " + b"a" * (MAX_TEMPLATE_BYTES + 10) + b"\n", "not a design template"),
], ids=["latin1", "binary", "png", "deep_nesting", "oversized"])
def test_undecodable_or_absurd_files_exit_2_naming_the_file(tmp_path, capsys, data, needle):
    path = _bad(tmp_path, data)
    out = tmp_path / "out"
    assert main(["build", str(path), "-o", str(out), "-q"]) == 2
    err = capsys.readouterr().err
    assert needle in err and str(path) in err
    assert "Traceback" not in err and err.count("\n") == 1
    assert not out.exists()


def test_a_folder_as_template_is_named(tmp_path, capsys):
    assert main(["build", str(tmp_path), "-o", str(tmp_path / "out"), "-q"]) == 2
    assert "is not a file" in capsys.readouterr().err
