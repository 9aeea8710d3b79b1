"""What a generated kernel is: a name, its SymPy arguments and outputs, and where it came from."""

from __future__ import annotations

import dataclasses

__all__ = ["Kernel"]


@dataclasses.dataclass
class Kernel:
    name: str
    args: tuple  # sympy symbols
    outputs: tuple  # sympy expressions (returned as a tuple if more than one)
    doc: str
    source: str  # derivation that produced it (module:function)
