"""The package surface: public names, lazy imports, no import cycles in the layers."""

import ast
import pathlib
import subprocess
import sys

import pytest

import bidmp

SRC = pathlib.Path(bidmp.__file__).parent


def test_public_names_resolve():
    for name in bidmp.__all__:
        assert getattr(bidmp, name) is not None
    assert bidmp.save.__name__ == "save_model" and bidmp.load.__name__ == "load_model"
    with pytest.raises(AttributeError, match="no attribute 'nothing'"):
        bidmp.nothing  # noqa: B018


def test_import_and_cli_help_do_not_import_numpy():
    code = "import sys, bidmp, bidmp.cli; bidmp.cli.build_parser(); print('numpy' in sys.modules)"
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.strip() == "False"


# Layers of ARCHITECTURE.md: a module may import only from its own or lower-numbered layers.
LAYERS = {
    "_checks": 1, "_threads": 1, "_noise": 1, "_trajectory": 1, "_integrate": 1, "_goals": 1, "_so3": 1,
    "_pose_time": 1, "_columns": 1, "_units": 1, "timing": 1, "dmp": 1, "segmentation": 1, "similarity": 1,
    "roadmap": 1, "bls": 1, "baselines": 1, "geometry": 1,
    "extension": 2, "incremental": 2, "cartesian": 2,
    "datasets": 3, "io": 3, "scenarios": 3, "metrics": 3, "evaluation": 3, "reproduce": 3, "plotting": 3, "_tables": 3,
    "sim": 3, "benchmark": 3,
    "cli": 4, "__main__": 4,
}


def bidmp_imports(path):
    """Top-level bidmp modules imported by ``path`` (relative imports resolved from its package)."""
    package = path.parent.relative_to(SRC).parts  # () for bidmp/, ("baselines",) for bidmp/baselines/
    tree = ast.parse(path.read_text())
    for node in ast.walk(tree):
        if isinstance(node, ast.ImportFrom) and node.level >= 1:
            base = list(package[: len(package) - (node.level - 1)]) if node.level - 1 <= len(package) else []
            parts = base + (node.module.split(".") if node.module else [])
            if parts:
                yield parts[0]
            else:
                yield from (alias.name for alias in node.names)
        elif isinstance(node, ast.ImportFrom) and node.module and node.module.startswith("bidmp."):
            yield node.module.split(".")[1]


def module_of(path):
    relative = path.relative_to(SRC).parts
    return relative[0] if len(relative) > 1 else path.stem


def test_modules_respect_the_layers():
    for path in SRC.rglob("*.py"):
        module = module_of(path)
        if module == "__init__":
            continue
        assert module in LAYERS, f"{module} is not placed in a layer of ARCHITECTURE.md"
        for imported in bidmp_imports(path):
            if imported in LAYERS and imported not in ("__init__", module):
                assert LAYERS[imported] <= LAYERS[module], f"{path.name} ({module}, layer {LAYERS[module]}) imports {imported}"


def test_no_import_cycles():
    graph = {}
    for path in SRC.rglob("*.py"):
        module = module_of(path)
        if module != "__init__":
            graph.setdefault(module, set()).update(m for m in bidmp_imports(path) if m in LAYERS and m != module)
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
    result = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, check=True)
    assert result.stdout.split() == ["svg", "False"]
    assert (tmp_path / "p.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_library_code_never_prints():
    for path in SRC.rglob("*.py"):
        if path.stem in ("cli", "__main__") or "cli" in path.relative_to(SRC).parts:
            continue
        calls = [
            node for node in ast.walk(ast.parse(path.read_text()))
            if isinstance(node, ast.Call) and getattr(node.func, "id", None) == "print"
        ]
        assert not calls, f"{path.name} calls print()"
