"""Bot files the start menu offers as opponents: the player's own, in the ``bots``
folder of the config folder (``$XDG_CONFIG_HOME/tanktool/bots/*.py``), and the
examples shipped beside the package (``examples/bots/*.py``).

A file is listed without running it: its source is parsed and every class with an
``act`` method is offered as ``FILE.py:Class`` (docs/bots.md).  A file that does not
parse is offered as ``FILE.py`` alone, so choosing it shows the loader's one-line error
(``sim.bots.loader``) in the menu instead of hiding it; a file without any bot class
(a helper module) is left out.  The bot is loaded when a match starts.
"""

from __future__ import annotations

import ast
from pathlib import Path

#: the examples' folder when tanktool runs from its source tree (an editable install)
EXAMPLES = Path(__file__).resolve().parents[2] / "examples" / "bots"


def bot_folders() -> list[Path]:
    """Where the menu looks for bot files: the user's folder first, then the examples."""
    from .input import config_dir

    return [config_dir() / "bots", EXAMPLES]


def find_bots(folders: list[Path] | None = None) -> list[str]:
    """Bot specs (``FILE.py:Class``) of the bot files in ``folders`` (default:
    :func:`bot_folders`), in folder order, then file and class name order."""
    specs: list[str] = []
    for folder in bot_folders() if folders is None else folders:
        if not folder.is_dir():
            continue
        for path in sorted(folder.glob("*.py")):
            try:
                tree = ast.parse(path.read_text(encoding="utf-8"), filename=str(path))
            except (OSError, SyntaxError, UnicodeDecodeError, ValueError):
                specs.append(str(path))              # chosen, it says what is wrong with it
                continue
            classes = sorted(n.name for n in tree.body if isinstance(n, ast.ClassDef) and any(
                isinstance(f, (ast.FunctionDef, ast.AsyncFunctionDef)) and f.name == "act" for f in n.body))
            specs += [f"{path}:{name}" for name in classes]
    return specs


def short(spec: str) -> str:
    """A spec as the menu shows it: ``Class (folder/file.py)``, or the name of a built-in."""
    path, sep, cls = spec.rpartition(":")
    if not sep or not path.endswith(".py"):
        path, cls = spec, ""
    if not path.endswith(".py"):
        return spec
    p = Path(path)
    where = f"{p.parent.name}/{p.name}"
    return f"{cls} ({where})" if cls else where
