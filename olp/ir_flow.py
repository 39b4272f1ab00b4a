"""The IR's statements beyond motion and I/O: what olp keeps but does not model.

Re-exported from :mod:`olp.ir` (``from olp.ir import Verbatim``). Like every IR node these are
frozen dataclasses with a ``span`` and a ``kind``, changed with ``dataclasses.replace``.

:class:`Verbatim` is the one vendor-specific node of the IR, on purpose: a statement a frontend
read, kept so that nothing is dropped, but whose meaning olp does not model (``$ACC.CP = 2.0``,
``ret = RSI_ON(#RELATIVE)``). A post of the same ``language`` writes its text unchanged; any
other post stops with an error naming the line. Passes treat it as taking no time and moving
nothing (which is the approximation: the controller may do more).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from typing import Literal

from olp.span import GENERATED, SourceSpan


class FlowError(ValueError):
    """A flow node was made with values it cannot hold (raised at construction)."""


_LINE_BREAKS = frozenset("\n\r\x0b\x0c\x1c\x1d\x1e\x85\u2028\u2029")


@dataclass(frozen=True, slots=True, kw_only=True)
class Verbatim:
    """A statement kept as its source text: ``text`` (one line, as the source spells it, without
    its comment), the ``language`` it is written in (a frontend's language, ``"krl"``), and
    ``reason``: why olp does not model it.

    The text can never become more than one statement of the output: it must be one line
    without control characters (checked here, and again by the post that writes it).
    """

    text: str
    language: str
    reason: str = ""
    span: SourceSpan = GENERATED
    kind: Literal["verbatim"] = field(default="verbatim", init=False)

    def __post_init__(self) -> None:
        if not self.text.strip():
            raise FlowError("Verbatim.text must hold a statement, got an empty text")
        bad = next((c for c in self.text if c in _LINE_BREAKS or (ord(c) < 32 and c != "\t")), None)
        if bad is not None:
            raise FlowError(f"Verbatim.text must be one line, found {bad!r} in {self.text!r}")
        if not self.language:
            raise FlowError("Verbatim.language must name the language of the text")
