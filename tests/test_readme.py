"""The README's Python example, as written there: it runs without any warning, and at the
default air data (which `simulate` and `identify` share) the truth lies within the bounds the
result reports."""

import re
import warnings
from pathlib import Path

import numpy as np

README = Path(__file__).resolve().parents[1] / "README.md"


def _python_example():
    text = README.read_text(encoding="utf-8")
    section = text[text.index("## From Python"):]
    return re.search(r"```python\n(.*?)```", section, re.S).group(1)


def test_readme_python_example_round_trips_without_warnings(capsys):
    code = _python_example()
    assert "pitotcal.simulate(plan" in code and "pitotcal.identify(flight" in code
    scope = {}
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        exec(compile(code, str(README), "exec"), scope)       # noqa: S102
    assert capsys.readouterr().out.strip()                  # the summary was printed
    flight, truth, result = scope["flight"], scope["truth"], scope["result"]
    assert flight.ps_pa is not None and flight.oat_k is not None
    assert result.air_data == truth.air_data == "compressible"
    assert result.success
    for name, value, std in zip(result.param_names, result.params, result.std):
        if name == "wind_from_deg":
            miss = (value - truth.parameters[name] + 180.0) % 360.0 - 180.0
        else:
            miss = value - truth.parameters[name]
        assert abs(miss) <= 2.0 * std, (name, value, truth.parameters[name], std)
    # and the airspeed correction the pilot uses: the truth's within the reported 2-sigma band
    from pitotcal.core.models import delta_v_kt, get_model

    rows = result.correction_table()
    assert len(rows) > 5
    vi = np.array([r["vi_kt"] for r in rows])
    true_dv = delta_v_kt(get_model(truth.model), truth.k, vi, "compressible")
    for row, want in zip(rows, true_dv):
        assert abs(row["dv_kt"] - want) <= row["dv_2sigma_kt"], (row, want)


def test_interfaces_doc_keeps_every_section():
    """docs/interfaces.md is the interfaces' reference: its sections are numbered 1, 2, ... with
    none missing and none cut short (an edit that replaced a span of it lost sections 4-20)."""
    import re

    text = (Path(__file__).resolve().parents[1] / "docs" / "interfaces.md").read_text()
    parts = re.split(r"^## (\d+)\. ", text, flags=re.M)
    numbers = [int(n) for n in parts[1::2]]
    assert numbers == list(range(1, len(numbers) + 1)) and len(numbers) >= 21, numbers
    for n, body in zip(numbers, parts[2::2]):
        assert len(body.splitlines()) >= 8, f"section {n} is {len(body.splitlines())} lines"
