"""The package's layers: no import circles, and no layer imports one above it.

Every import counts, also those inside functions (a lazy import still closes a circle).
"""

import ast
import importlib.util
import pkgutil
from pathlib import Path

import pytest

import pitotcal

# What each layer may import from pitotcal (its own layer included).
_BELOW_STUDIES = ("pitotcal.core", "pitotcal.io", "pitotcal.maneuvers", "pitotcal.estimation")
ALLOWED = {
    "pitotcal.core": ("pitotcal.core",),
    "pitotcal.io": ("pitotcal.core", "pitotcal.io"),
    "pitotcal.maneuvers": ("pitotcal.core", "pitotcal.io", "pitotcal.maneuvers"),
    "pitotcal.estimation": ("pitotcal.core", "pitotcal.io", "pitotcal.estimation"),
    "pitotcal.studies": (*_BELOW_STUDIES, "pitotcal.studies"),
}


# Subpackages installed from the repository's top-level folders (pyproject package-dir): not
# under pitotcal.__path__, so walked from their own location.
MAPPED = ("pitotcal.estimation", "pitotcal.maneuvers", "pitotcal.studies")


def _modules():
    """{module name: source path} of every module of the installed package."""
    found = {"pitotcal": Path(pitotcal.__file__)}
    roots = [(pitotcal.__path__, "pitotcal.")]
    for name in MAPPED:
        spec = importlib.util.find_spec(name)
        found[name] = Path(spec.origin)
        roots.append((spec.submodule_search_locations, name + "."))
    for path, prefix in roots:
        for info in pkgutil.walk_packages(path, prefix):
            spec = importlib.util.find_spec(info.name)
            if spec is not None and spec.origin and spec.origin.endswith(".py"):
                found[info.name] = Path(spec.origin)
    return found


def _imports(name, path, known):
    """The pitotcal modules that module `name` (source at `path`) imports."""
    package = name if path.name == "__init__.py" else name.rpartition(".")[0]
    out = set()
    for node in ast.walk(ast.parse(path.read_text(encoding="utf-8"))):
        if isinstance(node, ast.Import):
            targets = [alias.name for alias in node.names]
        elif isinstance(node, ast.ImportFrom):
            base = node.module or ""
            if node.level:
                parts = package.split(".")
                parts = parts[:len(parts) - node.level + 1]
                base = ".".join(parts + ([base] if base else []))
            # `from package import module` imports the module; else the names live in `base`
            targets = [f"{base}.{a.name}" if f"{base}.{a.name}" in known else base
                       for a in node.names]
        else:
            continue
        for target in targets:
            while target and target not in known:
                target = target.rpartition(".")[0]
            if target and target != name:
                out.add(target)
    return out


@pytest.fixture(scope="module")
def graph():
    modules = _modules()
    return {name: _imports(name, path, modules) for name, path in modules.items()}


def _cycle(graph):
    """One import circle as a list of modules, or None."""
    state = {}

    def visit(node, stack):
        state[node] = "open"
        stack.append(node)
        for nxt in sorted(graph.get(node, ())):
            if state.get(nxt) == "open":
                return stack[stack.index(nxt):] + [nxt]
            if nxt not in state:
                found = visit(nxt, stack)
                if found:
                    return found
        stack.pop()
        state[node] = "done"
        return None

    for node in sorted(graph):
        if node not in state:
            found = visit(node, [])
            if found:
                return found
    return None


def test_the_graph_sees_every_layer(graph):
    assert {"pitotcal.estimation.identification.oe", "pitotcal.maneuvers", "pitotcal.studies"} <= set(graph)
    assert "pitotcal.io.streams" in graph["pitotcal.io.logs"]
    assert "pitotcal.io.resample" in graph["pitotcal.io.timebase"]
    assert "pitotcal.core.measurement" in graph["pitotcal.io.flight_checks"]


def test_no_import_circles(graph):
    # the package's own lazy namespace (pitotcal/__init__.py) names modules only as strings
    inner = {name: {t for t in targets if t != "pitotcal"} for name, targets in graph.items()}
    assert _cycle(inner) is None, " -> ".join(_cycle(inner))


@pytest.mark.parametrize("layer", sorted(ALLOWED))
def test_lower_layers_import_nothing_above_them(graph, layer):
    wrong = {name: sorted(t for t in targets if t != "pitotcal" and not t.startswith(
                 tuple(f"{a}." for a in ALLOWED[layer]) + ALLOWED[layer]))
             for name, targets in graph.items() if name == layer or name.startswith(layer + ".")}
    assert {name: t for name, t in wrong.items() if t} == {}


# Inside a layer, its topic folders in the order they may import: a module may import its own
# topic and the topics ranked below it, never one ranked the same (a sibling) or above.
# "__init__" is the package's own namespace; top-level modules are named by their module name.
SUBLAYERS = {
    "pitotcal.estimation": {"uncertainty": 0, "robustness": 1, "identification": 2,
                            "survey": 2,
                            "monitor": 3, "legs": 3, "reporting": 4, "live": 5, "__init__": 6},
    "pitotcal.maneuvers": {"turbulence": 0, "plan": 1, "fly": 2, "__init__": 3},
    "pitotcal.studies": {"names": 0, "engine": 0, "accuracy": 1, "design": 1, "legs": 1,
                         "monitor": 1, "peers": 1, "real_alfa": 2, "jets": 2, "catalog": 3, "demo": 3,
                         "__init__": 4},
}


def _topic(layer, name):
    """The topic of module `name` inside `layer` ("__init__" for the layer itself)."""
    return "__init__" if name == layer else name[len(layer) + 1:].split(".")[0]


@pytest.mark.parametrize("layer", sorted(SUBLAYERS))
def test_topics_import_one_way(graph, layer):
    ranks = SUBLAYERS[layer]
    mine = [n for n in graph if n == layer or n.startswith(layer + ".")]
    assert {_topic(layer, n) for n in mine} <= set(ranks), "a topic with no rank in SUBLAYERS"
    wrong = sorted((n, t) for n in mine for t in graph[n] if t.startswith(layer + ".")
                   and _topic(layer, t) != _topic(layer, n)
                   and ranks[_topic(layer, t)] >= ranks[_topic(layer, n)])
    assert wrong == []


def test_a_circle_is_found():
    assert _cycle({"a": {"b"}, "b": {"c"}, "c": {"a"}}) == ["a", "b", "c", "a"]
    assert _cycle({"a": {"b"}, "b": set()}) is None


def test_a_command_never_imports_another_command(graph):
    shared = {"pitotcal.cli", "pitotcal.cli.common"}
    commands = {n for n in graph if n.startswith("pitotcal.cli.") and n not in shared}
    assert "pitotcal.cli.common" in graph["pitotcal.cli.identify"]
    # a command's own part (`identify_budget` of `identify`) is no command of its own
    wrong = {n: sorted(t for t in graph[n] & commands if not t.startswith(n + "_"))
             for n in commands}
    assert {n: t for n, t in wrong.items() if t} == {}



def test_the_readme_layout_names_every_topic_folder():
    """The README's layout table names each topic folder of the mapped layers as `name/`."""
    readme = Path(__file__).resolve().parents[1] / "README.md"
    if not readme.exists():
        pytest.skip(f"no README.md beside tests/ ({readme})")
    table = "\n".join(line for line in readme.read_text(encoding="utf-8").splitlines()
                      if line.lstrip().startswith("| "))
    missing = []
    for layer in SUBLAYERS:
        folder = Path(importlib.util.find_spec(layer).origin).parent
        for sub in sorted(p.name for p in folder.iterdir() if (p / "__init__.py").exists()):
            if f"`{sub}/`" not in table:
                missing.append(f"{layer}.{sub}")
    assert missing == []
