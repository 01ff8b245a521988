"""The package layout: one `sarcover` namespace, one-way imports, no cycles, nothing else installed."""

from __future__ import annotations

import ast
import shutil
import subprocess
import sys
import zipfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
SUBPACKAGES = ("formulations", "heuristics", "benchmarks", "reports")
# what each layer may import of the others (anything may import itself)
ALLOWED = {
    "formulations": set(),
    "heuristics": {"formulations"},
    "reports": {"formulations"},
    "benchmarks": {"formulations", "heuristics", "reports"},
}


def package_modules() -> dict[str, Path]:
    """Every installed module of the package: dotted name -> file."""
    mods = {"sarcover": ROOT / "__init__.py"}
    for sub in SUBPACKAGES:
        for path in sorted((ROOT / sub).rglob("*.py")):
            rel = path.relative_to(ROOT).with_suffix("")
            if not (path.parent / "__init__.py").exists():
                continue  # e.g. benchmarks/speed: not a package, not installed
            parts = ["sarcover", *rel.parts]
            if parts[-1] == "__init__":
                parts = parts[:-1]
            mods[".".join(parts)] = path
    return mods


def imports_of(path: Path, module: str, *, top_level_only: bool) -> set[str]:
    """The sarcover modules ``path`` imports (relative imports resolved). With ``top_level_only``
    only the imports that run when the module is imported (not those inside functions)."""
    tree = ast.parse(path.read_text())
    nodes = tree.body if top_level_only else list(ast.walk(tree))
    if top_level_only:  # imports under a module-level `if`/`try` also run at import
        nodes = [n for stmt in tree.body for n in ast.walk(stmt)
                 if not isinstance(stmt, (ast.FunctionDef, ast.AsyncFunctionDef, ast.ClassDef))]
    package = module if path.name == "__init__.py" else module.rpartition(".")[0]
    found = set()
    for node in nodes:
        if isinstance(node, ast.Import):
            found |= {a.name for a in node.names}
        elif isinstance(node, ast.ImportFrom):
            if node.level:
                base = package.split(".")
                base = base[: len(base) - node.level + 1]
                name = ".".join(base + ([node.module] if node.module else []))
            else:
                name = node.module or ""
            found.add(name)
            found |= {f"{name}.{a.name}" for a in node.names}
    return {n for n in found if n == "sarcover" or n.startswith("sarcover.")}


def layer(module: str) -> str | None:
    parts = module.split(".")
    return parts[1] if len(parts) > 1 and parts[1] in SUBPACKAGES else None


def test_layers_import_one_way():
    """formulations imports nothing above it, heuristics only formulations, reports only
    formulations; no subpackage imports the top-level API (lazy imports inside functions count)."""
    mods = package_modules()
    bad = []
    for name, path in mods.items():
        own = layer(name)
        if own is None:
            continue
        for imp in imports_of(path, name, top_level_only=False):
            other = layer(imp)
            if other is None and imp in mods and imp == "sarcover":
                bad.append(f"{name} imports the top-level sarcover API")
            elif other is not None and other != own and other not in ALLOWED[own]:
                bad.append(f"{name} imports {imp}")
    assert not bad, "\n".join(bad)


def import_graph(*, top_level_only: bool) -> dict[str, set[str]]:
    """Module -> the package modules it imports (``from pkg.mod import func`` counts as pkg.mod)."""
    mods = package_modules()
    graph = {}
    for name, path in mods.items():
        targets = set()
        for imp in imports_of(path, name, top_level_only=top_level_only):
            while imp and imp not in mods:  # `from pkg.mod import func` -> pkg.mod
                imp = imp.rpartition(".")[0]
            if imp and imp != name:
                targets.add(imp)
        graph[name] = targets
    return graph


def cycles(graph: dict[str, set[str]]) -> list[list[str]]:
    """The strongly connected components of more than one module (Tarjan)."""
    index, low, stack, on_stack, found = {}, {}, [], set(), []

    def strongconnect(v):
        index[v] = low[v] = len(index)
        stack.append(v)
        on_stack.add(v)
        for w in graph[v]:
            if w not in index:
                strongconnect(w)
                low[v] = min(low[v], low[w])
            elif w in on_stack:
                low[v] = min(low[v], index[w])
        if low[v] == index[v]:
            comp = []
            while True:
                w = stack.pop()
                on_stack.discard(w)
                comp.append(w)
                if w == v:
                    break
            if len(comp) > 1:
                found.append(sorted(comp))

    sys.setrecursionlimit(max(sys.getrecursionlimit(), 10 * len(graph)))
    for v in graph:
        if v not in index:
            strongconnect(v)
    return found


def test_no_module_level_import_cycle():
    """The graph of imports that run at import time has no cycle."""
    assert not cycles(import_graph(top_level_only=True))


def test_no_import_cycle_even_through_deferred_imports():
    """Counting the imports inside functions (and under ``TYPE_CHECKING``) too, no two modules
    import each other, directly or round a longer loop: deferring an import hides a cycle from
    Python, not from a reader."""
    assert not cycles(import_graph(top_level_only=False))


def test_the_cycle_check_sees_a_cycle():
    """A loop of three modules is one component; a module on no loop is none."""
    assert cycles({"a": {"b"}, "b": {"c"}, "c": {"a"}, "d": {"a"}}) == [["a", "b", "c"]]


def test_the_checks_see_a_cycle_and_a_wrong_way_import(tmp_path):
    """The import parser resolves relative and absolute imports (so the two checks above can fail)."""
    f = tmp_path / "m.py"
    f.write_text("from ..heuristics.greedy import greedy\nimport sarcover.reports.gaps\n"
                 "def g():\n    from sarcover.benchmarks import registry\n")
    assert imports_of(f, "sarcover.formulations.m", top_level_only=True) >= {
        "sarcover.heuristics.greedy", "sarcover.reports.gaps"}
    assert "sarcover.benchmarks.registry" in imports_of(f, "sarcover.formulations.m", top_level_only=False)
    assert "sarcover.benchmarks.registry" not in imports_of(f, "sarcover.formulations.m", top_level_only=True)


@pytest.fixture(scope="module")
def wheel(tmp_path_factory) -> Path:
    out = tmp_path_factory.mktemp("wheel")
    src = out / "src"  # a copy, so that the build leaves nothing in the checkout
    shutil.copytree(ROOT, src, ignore=shutil.ignore_patterns(".venv", ".git", "results", "build", "*.egg-info",
                                                            "__pycache__", ".pytest_cache", ".benchmarks"))
    subprocess.run([sys.executable, "-m", "pip", "wheel", "--no-deps", "-q", "-w", str(out), str(src)],
                   check=True, capture_output=True, timeout=600)
    return next(out.glob("sarcover-*.whl"))


def test_wheel_installs_only_the_sarcover_namespace(wheel):
    """The distribution's only top-level name is `sarcover`; tests, docs and the pytest-benchmark
    files stay out of it; the suites and TOP files ship inside it."""
    names = zipfile.ZipFile(wheel).namelist()
    tops = {n.split("/")[0] for n in names if not n.split("/")[0].endswith(".dist-info")}
    assert tops == {"sarcover"}
    top_level = next(n for n in names if n.endswith("top_level.txt"))
    assert zipfile.ZipFile(wheel).read(top_level).decode().split() == ["sarcover"]
    assert not [n for n in names if "/tests/" in n or "/docs/" in n or "bench_" in Path(n).name]
    assert "sarcover/benchmarks/suites/quick.toml" in names
    assert "sarcover/benchmarks/instances/top/p2.2.b.txt" in names
    assert "sarcover/benchmarks/instances/top/corrections.csv" in names
    assert "sarcover/benchmarks/instances/top/evidence/p4.4.n-977.json" in names
    assert "sarcover/formulations/bp/master.py" in names


def test_installed_wheel_imports_as_sarcover_only(wheel, tmp_path):
    """Installed from the wheel (not this checkout): `import sarcover` works and exposes its API;
    `import benchmarks` (or formulations, heuristics, reports) does not."""
    target = tmp_path / "site"
    subprocess.run([sys.executable, "-m", "pip", "install", "--no-deps", "-q", "--target", str(target), str(wheel)],
                   check=True, capture_output=True, timeout=600)
    code = ("import importlib.util, sarcover, sys\n"
            "print(sarcover.__file__)\n"
            "print([n for n in ('benchmarks', 'formulations', 'heuristics', 'reports') "
            "if importlib.util.find_spec(n) is not None])\n"
            "print(sarcover.list_methods()[0].name)\n")
    out = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True, text=True, timeout=120,
                         env={"PYTHONPATH": str(target), "PATH": "/usr/bin:/bin"}, check=True).stdout.splitlines()
    assert out[0].startswith(str(target))
    assert out[1] == "[]"
    assert out[2] == "greedy"
