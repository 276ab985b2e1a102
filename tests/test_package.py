"""The package's shape: one `pitotcal` namespace, the folders only inside it, and nothing that
points outside the repository (the layers: tests/test_layers.py)."""

import ast
import subprocess
import sys
from pathlib import Path

import pytest

import pitotcal

PUBLIC = ("identify", "read_flight", "plan_maneuver", "simulate", "Flight", "Plan",
          "IdentificationResult", "PitotcalError", "FlightDataError", "ObservabilityError",
          "PlanInfeasibleError")

def _package_sources():
    roots = [Path(p) for p in pitotcal.__path__]
    for sub in ("estimation", "maneuvers", "studies"):
        roots += [Path(p) for p in __import__(f"pitotcal.{sub}", fromlist=["_"]).__path__]
    return sorted({p for root in roots for p in root.rglob("*.py")})


def test_one_namespace():
    for name in PUBLIC:
        assert getattr(pitotcal, name) is not None, name
        assert name in dir(pitotcal)
    assert issubclass(pitotcal.FlightDataError, pitotcal.PitotcalError)
    with pytest.raises(AttributeError):
        pitotcal.no_such_name  # noqa: B018


def test_the_folders_are_not_top_level_packages(tmp_path):
    """`estimation`, `maneuvers` and `studies` are installed only inside `pitotcal`."""
    for name in ("estimation", "maneuvers", "studies"):
        run = subprocess.run([sys.executable, "-c", f"import {name}"], cwd=tmp_path,
                             capture_output=True, text=True, check=False)
        assert run.returncode != 0 and "No module named" in run.stderr, name
    run = subprocess.run([sys.executable, "-c", "import pitotcal.estimation, pitotcal.studies"],
                         cwd=tmp_path, capture_output=True, text=True, check=False)
    assert run.returncode == 0, run.stderr


def test_nothing_points_outside_the_repository():
    bad = [str(path) for path in _package_sources()
           if "../shared" in path.read_text() or "MEASURED.md" in path.read_text()
           or "INTERFACES" in path.read_text()]
    assert not bad, bad


@pytest.mark.parametrize("package", ["pitotcal", "pitotcal.maneuvers", "pitotcal.studies"])
def test_lazy_namespaces_list_and_load_their_names(package):
    module = __import__(package, fromlist=["_"])
    for name in module.__all__:
        assert name in dir(module)
        assert getattr(module, name) is not None
    with pytest.raises(AttributeError, match="has no attribute 'nope'"):
        module.nope  # noqa: B018


def test_subpackages_load_on_first_use_and_import_pitotcal_stays_cheap(tmp_path):
    """The README's `pitotcal.studies.run_study` and `pitotcal.maneuvers.check_autothrottle`
    work after `import pitotcal` alone, which loads no casadi, matplotlib, scipy or control."""
    code = ("import sys, pitotcal; "
            "heavy = sorted(m for m in ('casadi', 'matplotlib', 'scipy', 'control', "
            "'pitotcal.studies', 'pitotcal.maneuvers') if m in sys.modules); "
            "print(heavy, callable(pitotcal.studies.run_study), "
            "callable(pitotcal.maneuvers.check_autothrottle), "
            "pitotcal.estimation.identify is pitotcal.identify, "
            "{'studies', 'maneuvers', 'estimation', 'io', 'core'} <= set(dir(pitotcal)))")
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, check=True)
    assert run.stdout.strip() == "[] True True True True"
    with pytest.raises(AttributeError, match="has no attribute 'nope'"):
        pitotcal.nope  # noqa: B018


def test_the_command_line_starts_without_the_heavy_libraries(tmp_path):
    """Building the parser loads no numpy, casadi, matplotlib, scipy or studies."""
    code = ("import sys; from pitotcal.cli import build_parser; build_parser(); "
            "print(sorted(m for m in ('numpy', 'casadi', 'matplotlib', 'scipy', 'control', "
            "'pitotcal.studies.catalog') if m in sys.modules))")
    run = subprocess.run([sys.executable, "-c", code], cwd=tmp_path, capture_output=True,
                         text=True, check=True)
    assert run.stdout.strip() == "[]"


def _code_lines(tree, text):
    """Lines of code: not blank, not a comment, not inside a docstring."""
    docs = set()
    for node in ast.walk(tree):
        body = getattr(node, "body", None)
        if (isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef))
                and body and isinstance(body[0], ast.Expr)
                and isinstance(body[0].value, ast.Constant) and isinstance(body[0].value.value, str)):
            docs.update(range(body[0].lineno, body[0].end_lineno + 1))
    return sum(1 for i, line in enumerate(text.splitlines(), 1)
               if line.strip() and not line.strip().startswith("#") and i not in docs)


def test_modules_and_functions_stay_small():
    """Modules at most 400 lines of code (docstrings and comments not counted: a module's size
    follows its topic); functions at most ~80 lines (docstring included, 85 allowed)."""
    too_long = []
    for path in _package_sources():
        text = path.read_text()
        tree = ast.parse(text)
        if _code_lines(tree, text) > 400:
            too_long.append(f"{path.name}: {_code_lines(tree, text)} lines of code")
        for node in ast.walk(tree):
            if isinstance(node, (ast.FunctionDef, ast.AsyncFunctionDef)):
                length = node.end_lineno - node.lineno + 1
                if length > 85:
                    too_long.append(f"{path.name}:{node.lineno} {node.name}: {length} lines")
    assert not too_long, "\n".join(too_long)
