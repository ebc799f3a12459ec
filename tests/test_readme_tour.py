"""The README's tour: its ```console blocks are run and must print what they show
(times aside), so the documented outputs cannot go stale.  The runner and the rules
of the comparison are in tools/readme_tour.py; `python tools/readme_tour.py --update`
rewrites the README's outputs from a run when a command's output changes on purpose."""

from __future__ import annotations

import sys
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
sys.path.insert(0, str(ROOT / "tools"))
import readme_tour as tour  # noqa: E402

sys.path.remove(str(ROOT / "tools"))


def test_the_readme_tour_prints_what_it_shows(tmp_path):
    outcomes = tour.run_tour(tour.README.read_text(), tmp_path / "tour")
    # the tour covers every command, with real inputs of the checkout
    said = " ".join(o.cmd.text for o in outcomes)
    for command in ("import-arena", "build-navgrid", "import-vehicle", "check", "play"):
        assert f"tanktool {command}" in said
    bad = [o.report() for o in outcomes if not o.ok]
    assert not bad, ("the README's tour is stale (python tools/readme_tour.py --update rewrites it):\n\n"
                     + "\n\n".join(bad))
    # and it wrote only into its own folder
    written = {p.name for p in (tmp_path / "tour").iterdir()} - set(tour.LINKED)
    assert {"dungeon", "mytank", "courtyard", "yard", "r.json", "m.ttr"} <= written


README_LIKE = """intro
```console
$ tanktool play --seconds 2
box: 4 bots, 2 s
...
240 steps in 0.50 s: 480 steps/s, 4.0x real time
$ tanktool check x   # a comment
error: x: no such file or folder
```
```
$ tanktool not-run
```
"""


def test_blocks_commands_and_expected_lines_are_parsed():
    (block,) = tour.parse(README_LIKE)
    assert block.start == 2
    assert [c.text for c in block.commands] == ["tanktool play --seconds 2", "tanktool check x   # a comment"]
    assert [c.line for c in block.commands] == [3, 7]
    assert block.commands[0].expected[1] == "..."
    assert tour.wanted_status(block.commands[0]) == 0 and tour.wanted_status(block.commands[1]) == 2
    with pytest.raises(ValueError, match="never closed"):
        tour.parse("```console\n$ tanktool x\n")


@pytest.mark.parametrize("actual, ok", [
    (["box: 4 bots, 2 s", "240 steps in 0.91 s: 263 steps/s, 2.2x real time"], True),       # times differ
    (["box: 4 bots, 2 s", "bot1 ...", "bot2 ...", "240 steps in 1 s: 240 steps/s, 2x real time"], True),
    (["box: 5 bots, 2 s", "240 steps in 0.50 s: 480 steps/s, 4.0x real time"], False),       # a count differs
    (["box: 4 bots, 2 s", "241 steps in 0.50 s: 480 steps/s, 4.0x real time"], False),
    (["box: 4 bots, 2 s"], False),
])
def test_times_are_masked_and_dots_stand_for_lines(actual, ok):
    (block,) = tour.parse(README_LIKE)
    assert tour.matches(block.commands[0].expected, actual) is ok
    assert tour.mask("wrote dungeon in 1.03 s (5 ms), p99 6.203 ms") == "wrote dungeon in # s (# ms), p99 # ms"
    assert tour.mask("26,242 kg, 16 points, 3.139 m") == "26,242 kg, 16 points, 3.139 m"


def test_update_rewrites_outputs_and_keeps_elisions():
    (block,) = tour.parse(README_LIKE)
    a, b = block.commands
    outs = [tour.Outcome(a, 0, ["box: 4 bots, 2 s", "bot1", "bot2", "241 steps in 0.5 s"]),
            tour.Outcome(b, 2, ["error: x: no such file or folder (now longer)"])]
    new = tour.updated(README_LIKE, outs)
    (block2,) = tour.parse(new)
    assert block2.commands[0].expected == ["box: 4 bots, 2 s", "...", "241 steps in 0.5 s"]
    assert block2.commands[1].expected == ["error: x: no such file or folder (now longer)"]
    assert new.startswith("intro\n```console\n") and new.endswith("$ tanktool not-run\n```\n")
