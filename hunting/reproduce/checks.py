"""A small ledger of checks: thesis value beside ours, printed and saved as JSON."""
from __future__ import annotations

import json
import math
from dataclasses import dataclass, field
from pathlib import Path

from .._atomic import write_text


@dataclass
class Ledger:
    title: str
    rows: list = field(default_factory=list)

    def number(self, label: str, ours: float, thesis: float, tol: float, unit: str = "") -> bool:
        ok = bool(math.isfinite(ours) and abs(ours - thesis) <= tol)
        self.rows.append(dict(check=label, ours=float(ours), thesis=float(thesis), tolerance=tol, unit=unit, ok=ok))
        print(f"  {label:<58} ours {ours:>12.6g}  thesis {thesis:>10.6g} {unit:<6} {'ok' if ok else 'MISMATCH'}")
        return ok

    def fact(self, label: str, ours, thesis) -> bool:
        ok = bool(ours == thesis)
        self.rows.append(dict(check=label, ours=ours, thesis=thesis, ok=ok))
        print(f"  {label:<58} ours {str(ours):>12}  thesis {str(thesis):>10}        {'ok' if ok else 'MISMATCH'}")
        return ok

    def row(self, label: str) -> dict:
        """The check with this label (or the one check whose label starts with it)."""
        exact = [r for r in self.rows if r["check"] == label]
        if exact:
            return exact[0]
        (only,) = [r for r in self.rows if r["check"].startswith(label)]
        return only

    def on_figure(self, ax, items, *, loc: str = "lower right", title: str = "", room: float = 0.0) -> None:
        """Draw checks on a figure, thesis value beside ours: items are (short label, check
        label, format) (format for numbers; facts are written as they are); ``room``: see
        :func:`hunting.plotting.thesis_table`."""
        from ..plotting import thesis_table

        def text(v, fmt):
            if isinstance(v, bool):
                return "yes" if v else "no"
            if isinstance(v, (int, float)) and fmt:
                return format(v, fmt)
            return str(v)
        rows = []
        for short, label, fmt in items:
            r = self.row(label)
            rows.append((short, text(r["thesis"], fmt), text(r["ours"], fmt), ""))
        thesis_table(ax, rows, loc=loc, title=title, room=room)

    @property
    def failed(self) -> list:
        return [r["check"] for r in self.rows if not r["ok"]]

    def save(self, path: Path, extra: dict | None = None) -> None:
        write_text(path, json.dumps(dict(title=self.title, checks=self.rows, **(extra or {})), indent=2,
                                   default=float))

    def finish(self, out: Path) -> int:
        print(f"figures and results in {out}/")
        if self.failed:
            print("MISMATCH: " + "; ".join(self.failed))
            return 1
        print(f"{self.title}: all {len(self.rows)} checks match the thesis")
        return 0
