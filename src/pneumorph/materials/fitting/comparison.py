"""Several models fitted to the same data, side by side (:func:`compare`, :class:`FitComparison`):
R^2 per mode (Eqs A.1-A.3) as a text, Markdown or JSON table; the fits:
:mod:`pneumorph.materials.fitting.fit`.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

from pneumorph.checks import MODES
from pneumorph.materials.characterisation.testdata import TestCurve, TestData
from pneumorph.materials.fitting.fit import FitResult, fit, resolve_model


@dataclass(frozen=True, eq=False)
class FitComparison:
    """Several models fitted to the same data (:func:`compare`); renders like Table A.3."""

    results: tuple[FitResult, ...]
    data_name: str = ""

    @property
    def modes(self) -> tuple[str, ...]:
        return tuple(m for m in MODES if any(m in r.r2 for r in self.results))

    def rows(self) -> list[dict[str, Any]]:
        """One dict per model: name, R^2 per mode, overall R^2, mu0, Drucker stability."""
        return [{"model": r.model_name, **{f"r2_{m}": r.r2.get(m) for m in self.modes},
                 "r2_overall": r.r2_overall, "mu0_MPa": r.mu0, "drucker_stable": r.stability.is_stable}
                for r in self.results]

    def _cells(self) -> tuple[list[str], list[list[str]]]:
        head = ["model", *[f"R^2 {m}" for m in self.modes]]
        if len(self.modes) > 1:
            head.append("R^2 overall")
        head += ["mu0 [MPa]", "Drucker-stable"]
        body = []
        for r in self.results:
            row = [r.model_name, *[f"{r.r2[m]:.6f}" if m in r.r2 else "-" for m in self.modes]]
            if len(self.modes) > 1:
                row.append(f"{r.r2_overall:.6f}")
            bad = [m for m, (lo, hi) in r.stability.limits().items()
                   if lo > r.stability.stretch[0] or hi < r.stability.stretch[-1]]
            row += [f"{r.mu0:.4g}", "yes" if not bad else "no (" + ", ".join(bad) + ")"]
            body.append(row)
        return head, body

    def to_markdown(self) -> str:
        head, body = self._cells()
        lines = ["| " + " | ".join(head) + " |", "|" + "|".join("---" for _ in head) + "|"]
        return "\n".join(lines + ["| " + " | ".join(r) + " |" for r in body])

    def to_text(self) -> str:
        head, body = self._cells()
        widths = [max(len(x) for x in col) for col in zip(head, *body, strict=False)]
        fmt = "  ".join(f"{{:{w}s}}" for w in widths)
        rows = [head, ["-" * w for w in widths], *body]
        return "\n".join(fmt.format(*r).rstrip() for r in rows)

    def to_dict(self) -> dict[str, Any]:
        return {"data": self.data_name, "modes": list(self.modes), "table": self.rows(),
                "fits": [r.to_dict() for r in self.results]}

    def to_json(self) -> str:
        from pneumorph.io.files import strict_json

        return strict_json(self.to_dict(), indent=2)

    def render(self, fmt: str = "text") -> str:
        """``fmt`` one of ``text``, ``markdown``, ``json``."""
        return {"text": self.to_text, "markdown": self.to_markdown, "json": self.to_json}[fmt]()


def compare(model_names: Sequence[str], data: TestData | TestCurve, **options: Any) -> FitComparison:
    """Fit several models to the same data (options as for :func:`fit`).

    Examples
    --------
    >>> from pneumorph.materials.characterisation.datasets import load_dataset
    >>> t = compare(["neo-hooke", "mooney-rivlin-2"], load_dataset("treloar1944"))
    >>> print(t.to_markdown().splitlines()[0])
    | model | R^2 uniaxial | R^2 equibiaxial | R^2 planar | R^2 overall | mu0 [MPa] | Drucker-stable |
    """
    for name in model_names:
        resolve_model(name)  # fail before any fit
    results = tuple(fit(name, data, **options) for name in model_names)
    name = data.name if isinstance(data, TestData) else data.description
    return FitComparison(results, name)
