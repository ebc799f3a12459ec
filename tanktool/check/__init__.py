"""``tanktool check``: lint arena and vehicle bundles and wall lists.

:func:`run_check` finds what to check under some paths and returns a
:class:`Report` of :class:`Diagnostic` values; :data:`RULES` is the stable code table.
"""

from .diagnostics import RULES, Diagnostic
from .runner import Report, run_check

__all__ = ["RULES", "Diagnostic", "Report", "run_check"]
