"""The model kinds' registry is the one place that knows the model classes: model files read it,
``bidmp fit`` builds its flags from it, and nothing in the command line or the files asks a model
for its class (an AST scan). ProDMP, the newest kind, is its module plus its registry entry; what
else names it is listed here, so a new site is a decision, not an accident."""

from __future__ import annotations

import ast
from pathlib import Path

import numpy as np
import pytest

from bidmp.primitives import registry
from bidmp.primitives.promp import ProMP
from bidmp.primitives.registry import MODEL_KINDS, PrimitiveKind, kind_of, register_kind

SRC = Path(__file__).resolve().parents[1] / "src" / "bidmp"


def test_every_kind_loads_as_the_class_it_names():
    for name, kind in MODEL_KINDS.items():
        cls = kind.load()
        assert cls.__name__ == name and hasattr(cls, "to_state"), name


def _isinstance_on_kinds(folder: Path) -> list[str]:
    found = []
    for path in sorted(folder.rglob("*.py")):
        tree = ast.parse(path.read_text())
        for node in ast.walk(tree):
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "isinstance":
                names = {n.id for n in ast.walk(node.args[1]) if isinstance(n, ast.Name)}
                names |= {n.attr for n in ast.walk(node.args[1]) if isinstance(n, ast.Attribute)}
                if names & set(MODEL_KINDS):
                    found.append(f"{path.relative_to(SRC)}:{node.lineno}")
    return found


def test_the_command_line_and_the_files_never_ask_a_model_for_its_class():
    assert _isinstance_on_kinds(SRC / "cli") == []
    assert _isinstance_on_kinds(SRC / "io") == []


def test_the_newest_kind_is_its_modules_and_one_entry():
    """ProDMP is its modules — the primitive, its task method, its command-line adapter, each
    named prodmp.py, and the primitive's basis (prodmp_responses.py) — and one entry in the
    registry (exported by bidmp.primitives): nothing else in the package names it."""
    naming = {
        str(path.relative_to(SRC))
        for path in SRC.rglob("*.py")
        if "ProDMP" in path.read_text() and path.name not in ("prodmp.py", "prodmp_responses.py")
    }
    assert naming == {"primitives/registry.py", "primitives/__init__.py"}
    modules = {str(p.relative_to(SRC)) for p in SRC.rglob("prodmp.py")}
    assert modules == {"primitives/prodmp.py", "tasks/methods/prodmp.py", "cli/kinds/prodmp.py"}
    kind = MODEL_KINDS["ProDMP"]
    assert kind.adapter().fit_takes and kind.task_method().name == "prodmp"


def test_a_new_kind_gets_its_fit_flag_and_its_model_files(tmp_path, capsys):
    """A kind registered at run time: bidmp fit grows its flag; a model file of it saves and
    loads (the files read the registry); kind_of tells it from its look-alike parent."""
    from bidmp.cli import build_parser
    from bidmp.io import load_model, save_model

    kind = PrimitiveKind(
        "WideProMP", f"{__name__}:WideProMP", "several", fit_flag="wide-promp", summary="toy"
    )
    register_kind(kind)
    try:
        parser = build_parser()
        fit = next(a for a in parser._actions if a.dest == "command").choices["fit"]
        assert any("--wide-promp" in a.option_strings for a in fit._actions)
        # ... which refuses, in one line, to guess how to learn a kind it has no adapter for
        from bidmp.cli import main

        files = []
        for k in range(2):
            files.append(str(tmp_path / f"d{k}.csv"))
            demo_k = np.column_stack([np.linspace(0, 1, 50), np.sin(np.linspace(0, 3, 50)) + k])
            np.savetxt(files[-1], demo_k, delimiter=",", header="x,y", comments="")
        assert main(["fit", "--wide-promp", *files, "-o", str(tmp_path / "w.npz")]) == 2
        err = capsys.readouterr().err.strip().splitlines()
        assert len(err) == 1 and "no adapter for a WideProMP" in err[0]
        demo = np.column_stack([np.linspace(0, 1, 50), np.sin(np.linspace(0, 3, 50))])
        model = WideProMP(n_basis=6).fit([demo, demo + 0.1])
        assert kind_of(model) is kind
        assert kind_of(ProMP(n_basis=6).fit([demo, demo + 0.1])).name == "ProMP"
        loaded = load_model(save_model(model, tmp_path / "wide"))
        assert type(loaded) is WideProMP
        assert np.array_equal(loaded.weight_mean_, model.weight_mean_)
    finally:
        MODEL_KINDS.pop("WideProMP")
    with pytest.raises(ValueError, match="registered already"):
        register_kind(MODEL_KINDS["ProDMP"])
    with pytest.raises(ValueError, match="fit flag --prodmp"):
        register_kind(PrimitiveKind("Other", "x:Other", "several", fit_flag="prodmp"))
    assert "Other" not in registry.MODEL_KINDS


class WideProMP(ProMP):
    """A ProMP subclass, registered as a kind of its own in the test above."""


@pytest.fixture(scope="module")
def fitted_kinds(tmp_path_factory) -> dict:
    """One fitted model of every registered kind (the surface fuzz's own instances)."""
    import sys

    sys.path.insert(0, str(Path(__file__).parent))
    from surface_targets import _plain_instances

    found = {
        owner: instance
        for owner, instance, _ in _plain_instances(tmp_path_factory.mktemp("kinds"))
        if owner in MODEL_KINDS
    }
    assert set(found) == set(MODEL_KINDS), set(MODEL_KINDS) - set(found)
    return found


# Members a model file of an older format lacked, read with their default.
_OPTIONAL_MEMBERS = {"skill_time_scales_", "skill_start_logs_"}  # formats 2-4, format 3


def test_every_kinds_state_comes_back_as_the_same_model_and_a_bad_one_is_named(fitted_kinds):
    """The model-file protocol, public: ``from_state(*model.to_state())`` is the same model (every
    array equal, the state it gives again equal); a state with a member or a key taken away,
    or of another kind, is a ValueError naming what is missing — never a KeyError from inside."""
    from bidmp._state import StateError

    models = fitted_kinds
    for name, model in models.items():
        meta, arrays = model.to_state()
        again = type(model).from_state(meta, arrays)
        assert type(again) is type(model), name
        meta_again, arrays_again = again.to_state()
        assert meta_again == meta and arrays_again.keys() == arrays.keys(), name
        for member, value in arrays.items():
            assert np.array_equal(arrays_again[member], value), (name, member)
        for member in arrays:  # each one taken away: named, or one older formats lacked
            try:
                type(model).from_state(meta, {k: v for k, v in arrays.items() if k != member})
            except StateError as exc:
                assert f"missing member {member}" in str(exc), (name, member, str(exc))
            else:
                assert member.rsplit("/", 1)[-1] in _OPTIONAL_MEMBERS, (name, member)
        key = "params" if "params" in meta else sorted(meta)[0]
        with pytest.raises(ValueError, match=f"fitted {type(model).__name__}.*{key}"):
            type(model).from_state({k: v for k, v in meta.items() if k != key}, arrays)
        other = next(m for n, m in models.items() if n != name and type(m) is not type(model))
        with pytest.raises(ValueError, match=f"fitted {type(model).__name__}"):
            type(model).from_state(*other.to_state())
    with pytest.raises(TypeError, match="meta must be"):
        models["DMP"].from_state([], {})
    with pytest.raises(TypeError, match="arrays must map"):
        models["DMP"].from_state({}, [])


def test_every_kind_says_whether_it_is_fitted(fitted_kinds):
    """``check_fitted()``, one public method on every kind: a NotFittedError that says what to do
    before ``fit``, nothing after."""
    from bidmp import NotFittedError

    for model in fitted_kinds.values():
        model.check_fitted()
        with pytest.raises(NotFittedError, match="fit"):
            type(model)().check_fitted()
