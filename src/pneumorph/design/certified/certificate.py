"""The certificate of a certified search in words.

:func:`pneumorph.design.certified.search.certified_search` returns its certificate as a dict
(``CertifiedResult.certificate``, written to ``certificate.json``); :func:`certificate_text`
says what it certifies in a few lines: the verdict, the bound behind it, the tolerance
``epsilon`` and the designs it ties, and how many designs were verified by FE. The run's
report (``report.md``) and ``pneumorph design`` print these lines.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any


def _designs(n: int) -> str:
    return f"{n:,} design{'' if n == 1 else 's'}"


def certificate_text(certificate: Mapping[str, Any], unit: str, winner: str | None = None,
                     fidelity: str | None = None, show: int = 5) -> list[str]:
    """The certificate as a few lines of words.

    Parameters
    ----------
    certificate : mapping
        ``CertifiedResult.certificate``: ``certified``, ``designs_scored``, ``complete``,
        ``verified``, ``bound``, ``margin``, ``could_beat``, ``gap``, and optionally
        ``epsilon``, ``tied`` and ``floor``.
    unit : str
        The objective's unit (``mm``, ``deg``).
    winner : str, optional
        The FE-verified winner, named in the verdict.
    fidelity : str, optional
        The FE model's fidelity (``"3d"``), named with the verified designs.
    show : int
        The verified designs named (the others are counted).

    Returns
    -------
    list of str
        The verdict; the bound; the FE verifications.

    Examples
    --------
    >>> cert = {"certified": True, "designs_scored": 32768, "complete": True, "verified": ["0011", "0111"],
    ...         "bound": 0.4213, "bound_worst": 0.9, "margin": 1.0, "could_beat": 0, "gap": 0.0,
    ...         "epsilon": 0.05, "tied": 3}
    >>> print("\\n".join(certificate_text(cert, "mm", "0011", "3d")))
    Certified: of the 32,768 designs scored by the chain model, none can beat 0011 by more than epsilon =
    0.05 mm (3 designs could beat it by less than that: tied, not verified).
    Bound: the chain model's value of 0011 is within 0.421 mm of its FE value, of any design within 0.9 mm
    (the chain's validated centre errors x 1).
    Verified by FE (3d): 2 designs (0011, 0111).
    >>> cert.update(certified=False, could_beat=5, gap=0.31, epsilon=0.0, tied=0)
    >>> certificate_text(cert, "mm")[0]
    'Not certified: 5 designs not verified by FE could beat the winner by up to 0.31 mm (--certify verifies them).'
    """
    scored, verified = int(certificate["designs_scored"]), list(certificate["verified"])
    eps = float(certificate.get("epsilon", 0.0) or 0.0)
    tied = int(certificate.get("tied", 0) or 0)
    who = winner or "the winner"
    how = "scored by the chain model" if certificate.get("complete", True) else \
        "the chain model's branch-and-bound covers (every other design is worse by the chain)"
    if certificate["certified"]:
        verdict = f"Certified: of the {_designs(scored)} {how}, none can beat {who}"
        if eps > 0:
            verdict += f" by more than epsilon = {eps:g} {unit}"
            if tied:
                verdict += (f" ({_designs(tied)} could beat it by less than that: tied, not verified)")
        verdict += "."
    else:
        could = int(certificate["could_beat"])
        verdict = (f"Not certified: {_designs(could)} not verified by FE could beat {who} by up to "
                   f"{float(certificate['gap']):.3g} {unit}"
                   + (f" (more than epsilon = {eps:g} {unit})" if eps > 0 else "") + " (--certify verifies them).")
    worst = certificate.get("bound_worst")
    bound = (f"Bound: the chain model's value of {who} is within {float(certificate['bound']):.3g} {unit} of its FE "
             "value" + ("" if worst is None else f", of any design within {float(worst):.3g} {unit}")
             + f" (the chain's validated centre errors x {float(certificate['margin']):g}).")
    shown = ", ".join(verified[:show]) + (", ..." if len(verified) > show else "")
    fe = f"Verified by FE{f' ({fidelity})' if fidelity else ''}: {_designs(len(verified))} ({shown})."
    lines = [verdict, bound, fe]
    planar = certificate.get("planar")
    if planar:  # a library with sideways units: what the units that bend in the plane alone can do
        fe_value = planar.get("fe")
        value = "did not converge in the FE model" if fe_value is None else f"FE {float(fe_value):.4g} {unit}"
        lines.append(f"In the plane: the best design without sideways units is {planar['design']} (chain "
                     f"{float(planar['chain']):.4g} {unit}; {value}).")
    return lines


__all__ = ["certificate_text"]
