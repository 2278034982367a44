"""Hash every file of every shipped template's build: the before/after proof that a restructuring kept the
builds byte-identical.

    python tests/benchmarks/output_hashes.py > before.json      # on the old code
    python tests/benchmarks/output_hashes.py --compare before.json   # on the new: names every file that moved

Builds run in memory (``fabricate.pipeline.run_build``), nothing is written. STEP files are included when the
``cad`` extra is installed (the report records which).
"""

from __future__ import annotations

import argparse
import hashlib
import json
import sys


def hashes() -> dict[str, dict[str, str]]:
    """``{template: {relative path: sha256}}`` of every shipped design template's build."""
    from fabricate.design import load_design
    from fabricate.pipeline import run_build
    from fabricate.templates import shipped_templates

    out: dict[str, dict[str, str]] = {}
    for path in shipped_templates():
        outcome = run_build(load_design(path))
        out[path.stem] = {rel: hashlib.sha256(data).hexdigest() for rel, data in sorted(outcome.files.items())}
    return out


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--compare", metavar="JSON", help="hashes of an earlier run to compare with")
    args = parser.parse_args(argv)
    now = hashes()
    if not args.compare:
        json.dump(now, sys.stdout, indent=1, sort_keys=True)
        print()
        return 0
    with open(args.compare, encoding="utf-8") as fh:
        before = json.load(fh)
    moved = 0
    for name in sorted(set(before) | set(now)):
        a, b = before.get(name, {}), now.get(name, {})
        changed = sorted(p for p in set(a) | set(b) if a.get(p) != b.get(p))
        moved += len(changed)
        print(f"{name:28s} {len(b):4d} files  {'identical' if not changed else f'{len(changed)} differ'}")
        for rel in changed:
            print(f"    {rel}: {'only before' if rel not in b else 'only after' if rel not in a else 'differs'}")
    print(f"{moved} file(s) differ")
    return 1 if moved else 0


if __name__ == "__main__":
    sys.exit(main())
