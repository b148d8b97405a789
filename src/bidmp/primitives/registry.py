"""The model kinds: every class a model file may hold, with what the command line does with it.

One table, read by the model files (:mod:`bidmp.io.models`: which class a file names), by
``bidmp fit`` (a kind learned from several demonstrations adds its flag, ``--promp``,
``--prodmp``, …) and by ``bidmp rollout`` (a kind's family picks the rollout, its options are
the ones that family acts on) — so a new primitive is its module plus one :func:`register_kind` call
(or one entry in :data:`MODEL_KINDS`), and no code asks a model for its class.

Classes are named by their import path and imported only when used: this table imports
nothing, so it lives with the primitives and serves every layer above them.
"""

from __future__ import annotations

import importlib
from dataclasses import dataclass

__all__ = ["MODEL_KINDS", "PrimitiveKind", "kind_of", "model_class", "register_kind"]

# What bidmp rollout does with a family: "point" — a DMP to a goal (the pose, skill and robot
# options as the class allows); "rhythmic" — cycles of a rhythm; "several" — the mean of a
# distribution over several demonstrations, conditioned; "none" — not rolled out (a BLS).
FAMILIES = ("point", "rhythmic", "several", "none")


@dataclass(frozen=True)
class PrimitiveKind:
    """One kind of model.

    Attributes
    ----------
    name : str
        The class name a model file records.
    path : str
        ``"module:attribute"`` of the class.
    family : str
        What ``bidmp rollout`` does with it (:data:`FAMILIES`).
    poses : bool
        Its motions are poses (positions and unit quaternions).
    skills : bool
        It holds a skill library (``--skill`` picks one).
    fit_flag : str or None
        The ``bidmp fit`` flag that learns it from several demonstrations (``"prodmp"`` for
        ``--prodmp``), None for a kind learned otherwise.
    cli : str or None
        ``"module:attribute"`` of the command line's adapter of a kind learned from several
        demonstrations (what ``bidmp fit``'s options mean for it, how ``bidmp rollout``
        conditions it: :mod:`bidmp.cli.kinds`); None where the command line learns it otherwise.
    method : str or None
        ``"module:attribute"`` of its task method (:mod:`bidmp.tasks.methods`: ``bidmp demo``,
        ``sim``, the LASA benchmark), registered with the built-in methods; None for none.
    incremental : str or None
        ``"module:attribute"`` of the model that learns new skills on top of it (``bidmp extend``
        and ``bidmp learn``: a DMP becomes a Bi-DMP's skill 0); the kind itself where it is one;
        None where it cannot.
    summary : str
        One line for help texts.
    """

    name: str
    path: str
    family: str
    poses: bool = False
    skills: bool = False
    fit_flag: str | None = None
    cli: str | None = None
    method: str | None = None
    incremental: str | None = None
    summary: str = ""

    def __post_init__(self) -> None:
        if not isinstance(self.name, str) or not self.name.isidentifier():
            raise ValueError(f"name must be a class name, got {_quoted(self.name)}")
        for field_name in ("path", "incremental", "cli", "method"):
            value = getattr(self, field_name)
            if value is None and field_name != "path":
                continue
            if not isinstance(value, str) or value.count(":") != 1 or len(value) > 200:
                from .._checks import short_token  # not at import: the CLI's help needs no NumPy

                raise ValueError(
                    f"{field_name} must be 'module:attribute', got {short_token(value, 80)}"
                )
        if not isinstance(self.family, str) or self.family not in FAMILIES:
            raise ValueError(
                f"family must be one of {', '.join(FAMILIES)}, got {_quoted(self.family)}"
            )
        for field_name in ("poses", "skills"):
            if not isinstance(getattr(self, field_name), bool):
                raise TypeError(f"{field_name} must be True or False")
        flag = self.fit_flag
        if flag is not None and (
            not isinstance(flag, str) or not flag.replace("-", "").isalnum() or len(flag) > 40
        ):
            raise ValueError(
                f"fit_flag must be a flag's name (letters, digits, -), got {_quoted(flag)}"
            )
        if not isinstance(self.summary, str) or len(self.summary) > 500:
            raise TypeError("summary must be a line of text (at most 500 characters)")

    def load(self) -> type:
        """The class (imported now)."""
        return _import(self.path)

    def adapter(self):
        """The command line's adapter (imported now)."""
        if self.cli is None:
            raise ValueError(f"the command line has no adapter for a {self.name}")
        return _import(self.cli)

    def task_method(self):
        """Its task method (imported now), or None."""
        return None if self.method is None else _import(self.method)

    def grow(self, model):
        """``model`` as the model that learns new skills on it (itself if it is one)."""
        if self.incremental is None:
            raise ValueError(
                f"a {self.name} learns no new skills (a DMP, a Bi-DMP or a pose model does)"
            )
        if self.incremental == self.path:
            return model
        return _import(self.incremental)(model)


def _quoted(value, width: int = 40) -> str:
    """A refused value in one short line, without NumPy (the CLI's help imports this table): text
    quoted and cut, anything else by its type (an array's repr spans lines, a nested list's
    recurses)."""
    if not isinstance(value, str):
        return type(value).__name__
    text = "".join(c if c.isprintable() else "?" for c in value[: width + 1])
    return repr(text[:width] + "…") if len(text) > width else repr(text)


def _import(path: str):
    module, attribute = path.split(":")
    return getattr(importlib.import_module(module), attribute)


MODEL_KINDS: dict[str, PrimitiveKind] = {}


def register_kind(kind: PrimitiveKind, *, replace: bool = False) -> PrimitiveKind:
    """Add ``kind`` (by its class name); ``replace`` to change an existing one."""
    if not isinstance(kind, PrimitiveKind):
        raise TypeError(f"kind must be a PrimitiveKind, got {type(kind).__name__}")
    if kind.name in MODEL_KINDS and not replace:
        raise ValueError(f"a model kind {kind.name!r} is registered already (replace=True)")
    flags = {k.fit_flag for k in MODEL_KINDS.values() if k.name != kind.name and k.fit_flag}
    if kind.fit_flag is not None and kind.fit_flag in flags:
        raise ValueError(f"fit flag --{kind.fit_flag} is taken by another kind")
    MODEL_KINDS[kind.name] = kind
    return kind


for _kind in (
    PrimitiveKind(
        "DMP", "bidmp.primitives.dmp:DMP", "point", incremental="bidmp.incremental.bidmp:BiDMP",
        summary="a DMP",
    ),
    PrimitiveKind(
        "CartesianDMP", "bidmp.primitives.cartesian:CartesianDMP", "point", poses=True,
        incremental="bidmp.incremental.cartesian:CartesianBiDMP", summary="a pose DMP",
    ),
    PrimitiveKind(
        "BiDMP", "bidmp.incremental.bidmp:BiDMP", "point", skills=True,
        incremental="bidmp.incremental.bidmp:BiDMP",
        summary="a Bi-DMP (a DMP and its learned skills)",
    ),
    PrimitiveKind(
        "CartesianBiDMP", "bidmp.incremental.cartesian:CartesianBiDMP", "point", poses=True,
        skills=True, incremental="bidmp.incremental.cartesian:CartesianBiDMP",
        summary="a pose Bi-DMP",
    ),
    PrimitiveKind("BLS", "bidmp.incremental.bls:BLS", "none", summary="a Broad Learning System"),
    PrimitiveKind(
        "RhythmicDMP", "bidmp.primitives.rhythmic:RhythmicDMP", "rhythmic",
        summary="a rhythmic DMP",
    ),
    PrimitiveKind(
        "RhythmicPoseDMP", "bidmp.primitives.rhythmic_pose:RhythmicPoseDMP", "rhythmic",
        poses=True, summary="a rhythmic pose DMP",
    ),
    PrimitiveKind(
        "ProMP", "bidmp.primitives.promp:ProMP", "several", fit_flag="promp",
        cli="bidmp.cli.kinds.promp:ADAPTER",
        summary="a ProMP from several demonstrations (any lengths and rates); --n-kernels "
        "(default 20) basis functions per dimension",
    ),
    PrimitiveKind(
        "MultiDMP", "bidmp.primitives.multi:MultiDMP", "several", fit_flag="multi",
        cli="bidmp.cli.kinds.multi:ADAPTER",
        summary="a DMP from several demonstrations (aligned by phase, their spread kept)",
    ),
    PrimitiveKind(
        "ProDMP", "bidmp.primitives.prodmp:ProDMP", "several", fit_flag="prodmp",
        cli="bidmp.cli.kinds.prodmp:ADAPTER", method="bidmp.tasks.methods.prodmp:METHOD",
        summary="a ProDMP from several demonstrations (a DMP in closed form with a ProMP's "
        "distribution); --n-kernels (default 10) basis functions per dimension",
    ),
):  # fmt: skip
    register_kind(_kind)


def model_class(name: str) -> type:
    """The class of the model kind ``name`` (a model file's class name)."""
    if not isinstance(name, str) or name not in MODEL_KINDS:
        raise ValueError(
            f"name must be a registered model kind ({', '.join(sorted(MODEL_KINDS))}), "
            f"got {_quoted(name)}"
        )
    return MODEL_KINDS[name].load()


def kind_of(model) -> PrimitiveKind:
    """The registered kind of ``model`` (by its class's name and path; a subclass is not its
    parent's kind: it registers its own)."""
    cls = type(model)
    kind = MODEL_KINDS.get(cls.__name__)
    if kind is None or kind.path != f"{cls.__module__}:{cls.__qualname__}":
        raise ValueError(
            f"a {cls.__name__} is no registered model kind (known: {', '.join(sorted(MODEL_KINDS))})"
        )
    return kind
