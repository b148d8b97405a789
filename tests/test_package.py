"""The package surface: public names, lazy imports, no import cycles in the layers."""

import ast
import pathlib
import subprocess
import sys

import api_reference  # tools/: the documented packages, listed once
import pytest

import bidmp

SRC = pathlib.Path(bidmp.__file__).parent
ROOT = pathlib.Path(__file__).resolve().parent.parent


def test_public_names_resolve():
    for name in bidmp.__all__:
        assert getattr(bidmp, name) is not None
    assert bidmp.save.__name__ == "save_model" and bidmp.load.__name__ == "load_model"
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        bidmp.nothing  # noqa: B018


LAZY_PACKAGES = sorted(
    ".".join(("bidmp", *path.parent.relative_to(SRC).parts))
    for path in SRC.rglob("__init__.py")
    if "if TYPE_CHECKING:" in path.read_text()
)


@pytest.mark.parametrize("package", LAZY_PACKAGES)
def test_a_packages_public_names_are_the_imports_editors_see(package):
    """Structure guard: a package's lazily exported names are the imports of its ``if
    TYPE_CHECKING:`` block (what editors and type checkers read), each the very object the block
    names; nothing else is exported. No public name is also a submodule's: once that module is
    imported, Python sets the package's attribute to it (``from bidmp.demonstrations import
    prepare`` gave the module ``prepare.py`` after anything had imported it)."""
    import importlib
    import pkgutil

    from bidmp._lazy import typing_imports

    module = importlib.import_module(package)
    table = typing_imports(package, module.__file__)
    assert not set(table) & {info.name for info in pkgutil.iter_modules(module.__path__)}
    assert table and set(table) <= set(module.__all__)
    assert set(module.__all__) - set(table) <= {"__version__", *bidmp._SUBPACKAGES}
    for name, (source, attribute) in table.items():
        assert getattr(module, name) is getattr(importlib.import_module(source), attribute), name


def test_the_dmp_class_imports_neither_scikit_learn_nor_scipys_signal_package(loaded_after):
    """``import bidmp; bidmp.DMP`` takes 0.11 s: scikit-learn's ``base`` (0.6 s with the SciPy
    statistics it pulls in) is not imported for the estimators' conventions, nor SciPy's signal
    package (0.4 s); a fitted DMP still clones with scikit-learn."""
    code = "import bidmp; bidmp.DMP; bidmp.BiDMP; bidmp.CartesianDMP"
    assert loaded_after(code, ("sklearn", "scipy.signal", "scipy.stats")) == []
    from sklearn.base import clone

    model = bidmp.DMP(n_kernels=12, alpha=30.0)
    assert clone(model).get_params() == model.get_params()


def test_import_and_cli_help_do_not_import_numpy(loaded_after):
    code = "import bidmp, bidmp.cli; bidmp.cli.build_parser()"
    assert loaded_after(code, ("numpy",)) == []


# Layers of docs/architecture.md, by subpackage: a module may import only from its own or lower-numbered
# layers. 0: the package root's private helpers; 1: the math; 2: data and tasks (plotting sits
# here, not in 3: figures are data out, like files, and evaluation reports draw them; it imports
# only the math and io); 3: the application; 4: the shell.
LAYERS = {
    "_checks": 0,
    "_progress": 0,
    "_threads": 0,
    "_noise": 0,
    "_trajectory": 0,
    "_savgol": 0,
    "_units": 0,
    "_lazy": 0,
    "_state": 0,
    "_version": 0,
    "_api": 0,
    "_norms": 0,
    "primitives": 1,
    "extension": 1,
    "incremental": 1,
    "baselines": 1,
    "scene": 1,
    "planning": 1,
    "demonstrations": 2,
    "io": 2,
    "tasks": 2,
    "plotting": 2,
    "sim": 3,
    "experiments": 3,
    "cli": 4,
    "__main__": 4,
}


def bidmp_imports(path, root=SRC):
    """Subpackages (or root modules) of bidmp imported by ``path``, relative imports resolved."""
    package = path.parent.relative_to(
        root
    ).parts  # () for bidmp/, ("primitives",) for bidmp/primitives/
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level >= 1:
            base = (
                list(package[: len(package) - (node.level - 1)])
                if node.level - 1 <= len(package)
                else []
            )
            parts = base + (node.module.split(".") if node.module else [])
            if parts:
                yield parts[0]
            else:
                yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("bidmp."):
            yield node.module.split(".")[1]
        elif isinstance(node, ast.Import):
            yield from (
                alias.name.split(".")[1] for alias in node.names if alias.name.startswith("bidmp.")
            )


def module_of(path, root=SRC):
    relative = path.relative_to(root).parts
    return relative[0] if len(relative) > 1 else path.stem


def check_layers(root=SRC) -> None:
    """Every module of the tree at ``root`` placed in a layer and importing none above it."""
    for path in root.rglob("*.py"):
        module = module_of(path, root)
        if module == "__init__":
            continue
        assert module in LAYERS, f"{module} is not placed in a layer of docs/architecture.md"
        for imported in bidmp_imports(path, root):
            if imported in LAYERS and imported not in ("__init__", module):
                assert LAYERS[imported] <= LAYERS[module], (
                    f"{path.relative_to(root)} ({module}, layer {LAYERS[module]}) imports {imported}"
                )


def test_modules_respect_the_layers():
    check_layers()


def test_the_math_never_imports_files_scenarios_or_the_cli():
    """A guard with teeth beyond the layer numbers: no module of the math names io, tasks, sim or cli."""
    math = {name for name, layer in LAYERS.items() if layer <= 1}
    for path in SRC.rglob("*.py"):
        if module_of(path) in math:
            assert not set(bidmp_imports(path)) & {
                "io",
                "tasks",
                "sim",
                "cli",
                "experiments",
                "demonstrations",
                "plotting",
            }, path


def test_the_layer_check_sees_a_violation(tmp_path):
    """The checker itself can fail: an import of the CLI from the math is reported. The probe is
    a tree of its own (it once wrote into src/, where the tests running beside it read)."""
    root = tmp_path / "bidmp"
    for package in ("primitives", "cli"):
        (root / package).mkdir(parents=True)
        (root / package / "__init__.py").write_text("")
    (root / "primitives" / "dmp.py").write_text("from .. import _checks\n")
    check_layers(root)  # the probe's tree is fine ...
    (root / "primitives" / "_layer_probe.py").write_text("from ..cli import main\n")
    with pytest.raises(
        AssertionError, match=r"primitives/_layer_probe.py \(primitives, layer 1\) imports cli"
    ):
        check_layers(root)  # ... until the math imports the shell


def test_no_import_cycles():
    graph = {}
    for path in SRC.rglob("*.py"):
        module = module_of(path)
        if module != "__init__":
            graph.setdefault(module, set()).update(
                m for m in bidmp_imports(path) if m in LAYERS and m != module
            )
    state = {}

    def visit(module, trail):
        if state.get(module) == "done":
            return
        assert state.get(module) != "active", f"import cycle: {' -> '.join(trail + [module])}"
        state[module] = "active"
        for imported in sorted(graph.get(module, ())):
            visit(imported, trail + [module])
        state[module] = "done"

    for module in sorted(graph):
        visit(module, [])


def test_plotting_never_switches_the_matplotlib_backend(tmp_path):
    code = (
        "import matplotlib; matplotlib.use('svg'); import numpy as np; from bidmp.plotting import plot_trajectories;"
        f"plot_trajectories({str(tmp_path / 'p.png')!r}, np.random.default_rng(0).normal(size=(20, 3)));"
        "import sys; print(matplotlib.get_backend(), 'matplotlib.pyplot' in sys.modules)"
    )
    result = subprocess.run(
        [sys.executable, "-c", code], capture_output=True, text=True, check=True
    )
    assert result.stdout.split() == ["svg", "False"]
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_library_code_never_prints():
    for path in SRC.rglob("*.py"):
        if path.stem in ("cli", "__main__") or "cli" in path.relative_to(SRC).parts:
            continue
        calls = [
            node
            for node in ast.walk(ast.parse(path.read_text()))
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "print"
        ]
        assert not calls, f"{path.name} calls print()"


# Rooms are cut by cohesion (one idea per module, class and function), not by a line count: a module
# past this many lines usually holds more than one idea. Functions and classes are left to review
# (splitting one only to pass a count moves walls without making a room).
MAX_MODULE_LINES = 800


def oversized(text: str, name: str) -> list[str]:
    """``name`` when the module ``text`` is over :data:`MAX_MODULE_LINES` (every line counts)."""
    lines = len(text.splitlines())
    return [f"{name}: {lines} lines"] if lines > MAX_MODULE_LINES else []


def test_no_module_is_past_the_size_where_it_holds_two_ideas():
    """Structure guard."""
    found = [
        item
        for path in sorted(SRC.rglob("*.py"))
        for item in oversized(path.read_text(), str(path.relative_to(SRC)))
    ]
    assert not found, "modules past the size where they hold more than one idea:\n" + "\n".join(
        found
    )


def test_the_size_check_sees_a_long_module():
    """Structure guard: the probe that the check above can fail."""
    assert oversized("x = 1\n" * 800, "probe") == []
    assert oversized("x = 1\n" * 801, "probe") == ["probe: 801 lines"]


# --- the public surface is each package's __all__; everything else has an underscore --
API_PACKAGES = tuple(name for name in api_reference.PACKAGES if name != "bidmp")


def _owner(module_name: str) -> str:
    """The package whose __all__ must list a public name of ``module_name``: the deepest of
    API_PACKAGES that contains it."""
    return max(
        (p for p in API_PACKAGES if module_name == p or module_name.startswith(p + ".")), key=len
    )


def _unlisted(module, listed: set) -> list[str]:
    """Functions and classes defined in ``module`` whose names have no underscore and are not in
    ``listed`` (its package's public names)."""
    import inspect

    return [
        f"{module.__name__}.{name}"
        for name, value in vars(module).items()
        if not name.startswith("_")
        and (inspect.isfunction(value) or inspect.isclass(value))
        and getattr(value, "__module__", None) == module.__name__
        and name not in listed
    ]


def _public_modules():
    import importlib
    import pkgutil

    for info in pkgutil.walk_packages(bidmp.__path__, "bidmp."):
        if any(part.startswith("_") for part in info.name.split(".")[1:]) or info.name.startswith(
            "bidmp.cli"
        ):
            continue
        yield importlib.import_module(info.name)


def test_every_public_name_is_listed_and_nothing_else_is_reachable_without_an_underscore():
    import importlib

    stray = []
    for module in _public_modules():
        owner = importlib.import_module(_owner(module.__name__))
        stray += _unlisted(module, set(owner.__all__))
    assert not stray, stray
    for package in API_PACKAGES:
        module = importlib.import_module(package)
        for name in module.__all__:
            value = getattr(module, name)  # every listed name resolves ...
            if callable(value) and not isinstance(value, type(bidmp)):
                assert (value.__doc__ or "").strip(), (
                    f"{package}.{name} has no docstring"
                )  # ... and says what it is
        hidden = [
            name
            for name in dir(module)
            if not name.startswith("_")
            and name not in module.__all__
            and name != "annotations"
            and not isinstance(getattr(module, name), type(bidmp))
        ]
        assert not hidden, (package, hidden)


def test_the_surface_check_sees_an_unlisted_name():
    import types

    probe = types.ModuleType("bidmp.primitives.probe")
    exec("def helper():\n    pass\n\ndef _private():\n    pass\n", probe.__dict__)  # noqa: S102
    assert _unlisted(probe, set()) == ["bidmp.primitives.probe.helper"]
    assert _unlisted(probe, {"helper"}) == []
    assert _owner("bidmp.sim.pybullet.cell") == "bidmp.sim.pybullet"


def test_the_api_reference_is_current():
    result = subprocess.run(
        [sys.executable, str(ROOT / "tools" / "api_reference.py"), "--check"],
        capture_output=True,
        text=True,
        check=False,
    )
    assert result.returncode == 0, result.stderr


# --- imports: one way between modules, no private names across subpackages -------------------
def import_graph(root: pathlib.Path = SRC) -> tuple[dict, list]:
    """Every module's imports of other bidmp modules (deferred ones too; not those only a type
    checker reads), and the private names imported from another subpackage."""
    modules = {}
    for path in root.rglob("*.py"):
        parts = list(path.relative_to(root.parent).with_suffix("").parts)
        if parts[-1] == "__init__":
            parts = parts[:-1]
        modules[".".join(parts)] = path
    edges, private = {}, []
    for name, path in modules.items():
        tree = ast.parse(path.read_text())
        package = name if path.name == "__init__.py" else name.rsplit(".", 1)[0]
        typing_only = {
            id(node)
            for block in ast.walk(tree)
            if isinstance(block, ast.If) and "TYPE_CHECKING" in ast.unparse(block.test)
            for node in ast.walk(block)
        }
        edges[name] = set()
        for node in ast.walk(tree):
            if not isinstance(node, ast.ImportFrom) or id(node) in typing_only:
                continue
            if node.level:
                base = package.split(".")[: len(package.split(".")) - node.level + 1]
                target = ".".join(base + ([node.module] if node.module else []))
            else:
                target = node.module or ""
            if not target.startswith("bidmp"):
                continue
            for alias in node.names:
                module = f"{target}.{alias.name}" if f"{target}.{alias.name}" in modules else target
                edges[name].add(module)
                ours, theirs = _subpackage(name, root), _subpackage(module, root)
                # _checks, _units ...: the package's own internals, shared by every layer
                shared = not theirs and module.split(".")[-1].startswith("_")
                if (
                    alias.name.startswith("_")
                    and not alias.name.startswith("__")
                    and ours != theirs
                    and not shared
                ):
                    private.append(f"{name} imports {alias.name} from {module}")
    return {name: out & set(modules) for name, out in edges.items()}, private


def _subpackage(module: str, root: pathlib.Path) -> str:
    """The subpackage ``module`` belongs to ("" for the package's own top-level modules)."""
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and (root / parts[1]).is_dir() else ""


def cycles(edges: dict) -> list[list[str]]:
    """The groups of modules that import one another, directly or through others (Tarjan)."""
    index, low, stack, on, found, counter = {}, {}, [], set(), [], [0]

    def visit(node):
        index[node] = low[node] = counter[0]
        counter[0] += 1
        stack.append(node)
        on.add(node)
        for other in sorted(edges.get(node, ())):
            if other not in index:
                visit(other)
                low[node] = min(low[node], low[other])
            elif other in on:
                low[node] = min(low[node], index[other])
        if low[node] == index[node]:
            group = []
            while True:
                member = stack.pop()
                on.discard(member)
                group.append(member)
                if member == node:
                    break
            if len(group) > 1:
                found.append(sorted(group))

    for node in sorted(edges):
        if node not in index:
            visit(node)
    return found


def test_modules_import_one_another_one_way_only():
    """Structure guard: no new import cycle, deferred imports included."""
    edges, private = import_graph()
    found = cycles(edges)
    assert found == [], found
    assert private == [], "\n".join(private)


def test_the_cycle_check_sees_a_cycle(tmp_path):
    """Structure guard: the probe that the check above can fail."""
    package = tmp_path / "bidmp"
    package.mkdir()
    (package / "__init__.py").write_text("")
    (package / "a.py").write_text("def f():\n    from .b import g\n")
    (package / "b.py").write_text("from .a import f\nfrom .c import _h\n")
    (package / "c.py").write_text("")
    (package / "sub").mkdir()
    (package / "sub" / "__init__.py").write_text("")
    (package / "sub" / "d.py").write_text("from ..c import _h\n")
    edges, private = import_graph(package)
    assert cycles(edges) == [["bidmp.a", "bidmp.b"]]
    assert private == ["bidmp.sub.d imports _h from bidmp.c"]
