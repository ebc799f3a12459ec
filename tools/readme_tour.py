"""Run the README's tour and compare what the commands print with what it shows.

    python tools/readme_tour.py            # run every tour block, report differences
    python tools/readme_tour.py --update   # rewrite the README's outputs from a run

The tour blocks are the README's fenced blocks opened with ```` ```console ````
(other blocks are illustrations and are not run).  In them, a line starting ``$ ``
is a command; the commands of all blocks run in README order in one fresh folder
that sees the checkout's ``tests/``, ``arenas/`` and ``vehicles/`` (so paths are
written as from the checkout's root, and a later block uses what an earlier one
wrote, as a reader following the tour does); the lines after a command, up to the
next one, are what it prints (stdout and stderr, as they come).  The comparison:

- a line ``...`` stands for any number of lines (none included);
- times are not compared: a number followed by ``s``, ``ms``, ``steps/s`` or
  ``x real time`` matches any number (so are p50/p99 latencies in ms);
- every other line must be the same, apart from trailing spaces;
- a command must exit 0, or 2 when its output shows an ``error:`` line.

``--update`` replaces each command's expected lines with what it printed; where the
old ones had a ``...`` line, the lines before and after it are kept to the same
count around a ``...`` (so a long scoreboard stays elided).
"""

from __future__ import annotations

import os
import re
import shlex
import subprocess
import sys
import tempfile
from dataclasses import dataclass, field
from pathlib import Path

ROOT = Path(__file__).resolve().parent.parent
README = ROOT / "README.md"
#: what a tour's working folder sees of the checkout
LINKED = ("tests", "arenas", "vehicles")
#: seconds one command may take before it is called stuck
TIMEOUT = 300

_TIME = re.compile(r"\d[\d,]*(?:\.\d+)?(?=(?: ?(?:ms|s)\b| steps/s|x real time))")


@dataclass
class Command:
    line: int                       # 1-based line of the ``$`` in the README
    text: str                       # the command as written (after ``$ ``)
    expected: list[str] = field(default_factory=list)


@dataclass
class Block:
    start: int                      # 1-based line of the opening fence
    commands: list[Command] = field(default_factory=list)


def parse(text: str) -> list[Block]:
    """The ```console blocks of a README and their commands."""
    blocks: list[Block] = []
    current: Block | None = None
    for no, line in enumerate(text.splitlines(), 1):
        if current is None:
            if line.strip() == "```console":
                current = Block(no)
            continue
        if line.strip() == "```":
            blocks.append(current)
            current = None
        elif line.startswith("$ "):
            current.commands.append(Command(no, line[2:]))
        elif current.commands:
            current.commands[-1].expected.append(line.rstrip())
    if current is not None:
        raise ValueError(f"README.md:{current.start}: ```console block is never closed")
    return blocks


def mask(line: str) -> str:
    """A line with its times replaced by ``#`` (they differ from run to run)."""
    return _TIME.sub("#", line.rstrip())


def matches(expected: list[str], actual: list[str]) -> bool:
    """Whether ``actual`` lines fit ``expected`` (``...`` = any lines, times masked)."""
    exp = [mask(e) for e in expected]
    act = [mask(a) for a in actual]

    def fit(i: int, j: int) -> bool:
        if i == len(exp):
            return j == len(act)
        if exp[i] == "...":
            return any(fit(i + 1, k) for k in range(j, len(act) + 1))
        return j < len(act) and exp[i] == act[j] and fit(i + 1, j + 1)

    return fit(0, 0)


def run(cmd: Command, cwd: Path) -> tuple[int, list[str]]:
    """Run one ``tanktool ...`` command in ``cwd``; its exit status and output lines."""
    args = shlex.split(cmd.text, comments=True)
    if not args or args[0] != "tanktool":
        raise ValueError(f"README.md:{cmd.line}: a tour command must start with 'tanktool', got {cmd.text!r}")
    env = dict(os.environ, SDL_VIDEODRIVER="dummy", SDL_AUDIODRIVER="dummy", PYTHONUNBUFFERED="1",
               COLUMNS="200")
    out = subprocess.run([sys.executable, "-m", "tanktool", *args[1:]], cwd=cwd, env=env, text=True,
                         stdout=subprocess.PIPE, stderr=subprocess.STDOUT, timeout=TIMEOUT)
    return out.returncode, [ln.rstrip() for ln in out.stdout.splitlines()]


def wanted_status(cmd: Command) -> int:
    return 2 if any(line.startswith("error:") for line in cmd.expected) else 0


def tour_folder(base: Path) -> Path:
    """A fresh working folder that sees the checkout's inputs (read only, by links)."""
    base.mkdir(parents=True, exist_ok=True)
    for name in LINKED:
        (base / name).symlink_to(ROOT / name, target_is_directory=True)
    return base


@dataclass
class Outcome:
    cmd: Command
    status: int
    output: list[str]

    @property
    def ok(self) -> bool:
        return self.status == wanted_status(self.cmd) and matches(self.cmd.expected, self.output)

    def report(self) -> str:
        lines = [f"README.md:{self.cmd.line}: $ {self.cmd.text}"]
        if self.status != wanted_status(self.cmd):
            lines.append(f"  exit status {self.status}, expected {wanted_status(self.cmd)}")
        lines.append("  expected:")
        lines += [f"    {e}" for e in self.cmd.expected]
        lines.append("  printed:")
        lines += [f"    {a}" for a in self.output]
        return "\n".join(lines)


def run_tour(text: str, workdir: Path) -> list[Outcome]:
    """Every command of every tour block, in order, in ``workdir`` (made a tour folder)."""
    cwd = tour_folder(workdir)
    out = []
    for block in parse(text):
        for cmd in block.commands:
            status, printed = run(cmd, cwd)
            out.append(Outcome(cmd, status, printed))
    return out


def updated(text: str, outcomes: list[Outcome]) -> str:
    """The README with each command's expected lines replaced by what it printed."""
    lines = text.splitlines()
    by_line = {o.cmd.line: o for o in outcomes}
    result: list[str] = []
    skip = 0
    for no, line in enumerate(lines, 1):
        if skip:
            skip -= 1
            continue
        result.append(line)
        o = by_line.get(no)
        if o is None:
            continue
        old = o.cmd.expected
        skip = len(old)
        new = o.output
        if "..." in old:
            head, tail = old.index("..."), len(old) - 1 - max(i for i, e in enumerate(old) if e == "...")
            if head + tail < len(new):
                new = new[:head] + ["..."] + (new[len(new) - tail:] if tail else [])
        result.extend(new)
    return "\n".join(result) + ("\n" if text.endswith("\n") else "")


def main(argv: list[str]) -> int:
    update = "--update" in argv
    text = README.read_text()
    with tempfile.TemporaryDirectory(prefix="tanktool-tour-") as tmp:
        outcomes = run_tour(text, Path(tmp) / "tour")
    bad = [o for o in outcomes if not o.ok]
    for o in bad:
        print(o.report(), end="\n\n")
    print(f"{len(outcomes) - len(bad)} of {len(outcomes)} tour commands print what the README shows")
    if update and bad:
        tmp = README.with_name(".README.md.tmp")
        tmp.write_text(updated(text, outcomes))
        os.replace(tmp, README)                     # never a half-written README
        print(f"updated {README.relative_to(ROOT)}: check the diff (git diff README.md)")
        return 0
    return 1 if bad else 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))
