"""The builder's findings: every problem ``moas-server --check`` reports, in its words,
each with the path of the field it is about.

:func:`check_text` reads a draft's text as the server would (the same reader and
checks), so what it finds is what the running server would refuse or warn about; when
asked, it adds the station plan's findings too, within a processor-time budget.  It is
a pure function of the text: the window runs it off its thread, on a timer after the
last keystroke.
"""

from __future__ import annotations

import sys
from dataclasses import dataclass
from pathlib import Path as FilePath

from moas_gui.config.jsontree import Node, parse
from moas_gui.config.loader import parse_config
from moas_gui.config.model import Config
from moas_gui.config.problems import Severity

from .spans import Path, PlaceIndex

PLAN = "finding"
"""The severity word of a station plan's finding (the checks' are "error" and "warning")."""


@dataclass(frozen=True, slots=True)
class CheckFinding:
    """One thing the checks found: ``text`` is the line ``--check`` prints for it."""

    severity: str
    message: str
    line: int
    column: int
    path: Path
    text: str

    @property
    def is_error(self) -> bool:
        return self.severity == Severity.ERROR.value


@dataclass(frozen=True, slots=True)
class Checked:
    """The findings of one text (``config``: the configuration, None when it has errors)."""

    text: str
    findings: tuple[CheckFinding, ...]
    config: Config | None
    plan_note: str = ""
    """Why the plan's findings are missing (too large to plan in time, or errors)."""

    @property
    def errors(self) -> tuple[CheckFinding, ...]:
        return tuple(f for f in self.findings if f.is_error)

    @property
    def warnings(self) -> tuple[CheckFinding, ...]:
        return tuple(f for f in self.findings if f.severity == Severity.WARNING.value)


def check_text(text: str, filename: str = "<config>", *, root: Node | None = None,
               plan_seconds: float = 0.0, platform: str = sys.platform) -> Checked:
    """Every problem of ``text`` (read as the file ``filename``), each with its field's
    path (``root``: the text's tree, when the caller has it); with ``plan_seconds`` above
    0, also the station plan's findings, if the plan is made within that much processor
    time."""
    result = parse_config(text, filename, FilePath(filename), platform=platform)
    if root is None:
        root, _ = parse(text, filename)
    places = PlaceIndex(root)
    findings = [CheckFinding(p.severity.value, p.message, p.line, p.column,
                        places.path_at(p.line, p.column), str(p)) for p in result.problems]
    note = ""
    if plan_seconds > 0 and result.config is not None:
        plan_findings, note = _plan_findings(result.config, text, filename, places, plan_seconds)
        findings += plan_findings
    return Checked(text, tuple(findings), result.config, note)


def _plan_findings(config: Config, text: str, filename: str, places: PlaceIndex,
                   seconds: float) -> tuple[list[CheckFinding], str]:
    from moas_gui.engine import EngineError
    from moas_gui.plan import PlanTooLong, build_plan, deadline_after

    try:
        plan = build_plan(config, filename, text, deadline_after(seconds))
    except PlanTooLong:
        return [], (f"the station plan's findings are not shown: the station is too large "
                    f"to plan within {seconds:g} s (moas-server --plan {filename})")
    except EngineError as exc:
        return [], f"the station plan cannot be made: {exc}"
    out = []
    for finding in plan.findings:
        where = f"{filename}:{finding.line}" if finding.line else filename
        out.append(CheckFinding(PLAN, finding.text, finding.line, 0,
                           places.path_on_line(finding.line), f"{where}: {finding.text}"))
    return out, ""


__all__ = ["PLAN", "CheckFinding", "Checked", "check_text"]
