"""The toy model, slowed: each design takes ``seconds`` (for faults injected while designs are being solved)."""

from __future__ import annotations

import time

from tests.design.toy_model import ToyModel


class SlowToy(ToyModel):
    """:class:`ToyModel` whose every evaluation first sleeps ``seconds``."""

    def __init__(self, seconds: float = 1.0, **kw: object) -> None:
        super().__init__(**kw)  # type: ignore[arg-type]
        self.seconds = seconds

    def fingerprint(self) -> str:
        return super().fingerprint() + f"slow{self.seconds}"

    def evaluate(self, orientation: str):  # type: ignore[no-untyped-def]
        time.sleep(self.seconds)
        return super().evaluate(orientation)
