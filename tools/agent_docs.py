"""Write the agents' transition table (``sim.agents.agent.TRANSITIONS``) into
docs/agents.md, so the docs show what the code runs.

    .venv/bin/python tools/agent_docs.py [--check]

The table goes in the fenced block after the line ``MARK`` below; ``--check`` only
says whether the docs are up to date (exit 1 when not).
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT))

from tanktool.sim.agents.agent import transition_table  # noqa: E402

DOC = ROOT / "docs" / "agents.md"
MARK = "<!-- the transition table, written by tools/agent_docs.py from agent.TRANSITIONS -->"


def with_table(text: str) -> str:
    """``text`` (the docs) with the block after ``MARK`` replaced by the table."""
    at = text.find(MARK)
    if at < 0:
        raise ValueError(f"{DOC}: no line {MARK!r} to put the table after")
    start = text.index("```\n", at) + 4
    end = text.index("```", start)
    return text[:start] + transition_table() + "\n" + text[end:]


def main(argv: list[str] | None = None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("--check", action="store_true", help="only check that the docs are up to date")
    args = ap.parse_args(argv)
    text = DOC.read_text(encoding="utf-8")
    try:
        new = with_table(text)
    except ValueError as e:
        print(f"error: {e}", file=sys.stderr)
        return 2
    if args.check:
        if new != text:
            print(f"{DOC}: the transition table is out of date (run tools/agent_docs.py)", file=sys.stderr)
            return 1
        return 0
    if new != text:
        DOC.write_text(new, encoding="utf-8")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
