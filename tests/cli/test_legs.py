"""`pitotcal legs`: summary, JSON `points` and `global`, figure, exit statuses 0/2/3."""

import hashlib
import json
from pathlib import Path

import pytest
from pitotcal.estimation.legs.report import POINT_KEYS

from pitotcal.cli import main

EXAMPLE = Path(__file__).resolve().parents[2] / "docs" / "legs-example.csv"
HEADER = "point,ias_kt,pressure_alt_ft,oat_c,groundspeed_kt,track_deg\n"


def _sha(path):
    return hashlib.sha256(Path(path).read_bytes()).hexdigest()


def test_example_summary_json_and_figure(tmp_path, capsys):
    before = _sha(EXAMPLE)
    out_json, out_png = tmp_path / "legs.json", tmp_path / "legs.png"
    status = main(["legs", str(EXAMPLE), "--json", str(out_json), "--plot", str(out_png)])
    captured = capsys.readouterr()
    assert status == 0, captured.err
    assert _sha(EXAMPLE) == before
    assert captured.out.startswith(f"Legs: {EXAMPLE} (23 legs, 6 points)")
    assert "Global fit over all legs: inverse" in captured.out and "KCAS" in captured.out
    assert "point 6: three legs and no groundspeed_sd_kt: no bound" in captured.err
    d = json.loads(out_json.read_text())
    assert [tuple(p) for p in d["points"]] == [POINT_KEYS] * 6
    assert [p["method"] for p in d["points"]] == ["4-leg"] * 5 + ["3-leg"]
    assert d["points"][5]["dv_2sigma_kt"] is None
    g = d["global"]
    assert g["model"] == "inverse" and g["converged"] and g["n_samples"] == 23
    # the example's truth (its header): k1 = 0.03, k2 = -40 Pa, wind 18 kt from 230°
    for name, true in (("k1", 0.03), ("k2", -40.0)):
        assert abs(g["parameters"][name]["value"] - true) < 3 * g["parameters"][name]["std"]
    assert abs(g["winds"][0]["wind_speed_kt"] - 18) < 1.5
    assert out_png.stat().st_size > 20_000


def _file(tmp_path, rows):
    path = tmp_path / "legs.csv"
    path.write_text(HEADER + "".join(rows))
    return path


def test_north_east_south_three_legs_accepted(tmp_path, capsys):
    """A three-leg N/E/S pattern (the track turns only 180°) determines TAS and wind."""
    path = _file(tmp_path, ["1,120,3000,10,110.0,0\n", "1,120,3000,10,135.0,90\n",
                            "1,120,3000,10,140.0,180\n"])
    out_json = tmp_path / "r.json"
    assert main(["legs", str(path), "--json", str(out_json)]) == 0
    d = json.loads(out_json.read_text())
    assert d["points"][0]["method"] == "3-leg" and d["global"] is None
    assert any("no global fit" in w for w in d["warnings"])
    capsys.readouterr()


def test_collinear_tracks_refused_exit_3(tmp_path, capsys):
    path = _file(tmp_path, ["1,120,3000,10,110.0,0\n", "1,120,3000,10,135.0,180\n",
                            "1,120,3000,10,112.0,0\n"])
    assert main(["legs", str(path)]) == 3
    err = capsys.readouterr().err
    assert err.count("\n") == 1 and "lie on one line in the velocity plane" in err
    assert err.startswith("pitotcal legs: ")


@pytest.mark.parametrize("args, match", [
    (["--wind", "global"], "--wind 'global' is not one of per-band, per-point"),
    (["--model", "cubic"], "--model 'cubic' is not one of"),
])
def test_bad_options_exit_2(args, match, capsys):
    assert main(["legs", str(EXAMPLE), *args]) == 2
    err = capsys.readouterr().err
    assert match in err and err.count("\n") == 1


def test_bad_cell_exit_2_naming_column_and_row(tmp_path, capsys):
    path = _file(tmp_path, ["1,120,3000,10,110.0,0\n", "1,120,3000,10,fast,90\n"])
    assert main(["legs", str(path)]) == 2
    err = capsys.readouterr().err
    assert "column groundspeed_kt, row 2 (line 3): 'fast' is not a number" in err


def test_output_on_top_of_input_refused(capsys):
    assert main(["legs", str(EXAMPLE), "--json", str(EXAMPLE)]) == 2
    assert "would overwrite the input leg file" in capsys.readouterr().err


def test_indicated_total_temperature_file_gives_the_static_one(tmp_path, capsys):
    """The example's OAT turned into the indicated total temperature (tat_c) a probe of
    recovery factor 0.8 reads at each leg's true Mach (the example's truth: Δp/q_c = 0.03 −
    40 Pa/q_ci): with --temp-recovery 0.8 the result is the example's own to 0.01 kt (each
    point converts at its own estimate of the position error, which its scatter moves)."""
    import csv
    import io

    import numpy as np

    from pitotcal.core import airdata
    from pitotcal.core.units import FT_TO_M, KT_TO_MPS

    lines = EXAMPLE.read_text().splitlines()
    body = [ln for ln in lines if ln and not ln.startswith("#")]
    rows = list(csv.DictReader(io.StringIO("\n".join(body))))
    for r in rows:
        qci = float(airdata.qc_from_cas_pa(float(r["ias_kt"]) * KT_TO_MPS))
        qc = qci / (1.0 - (0.03 - 40.0 / qci))
        ps = airdata.static_pressure_pa(float(r["pressure_alt_ft"]) * FT_TO_M) + qci - qc
        mach = float(airdata.mach_from_qc(qc, ps))
        t_s = float(r.pop("oat_c")) + 273.15
        r["tat_c"] = f"{t_s * (1 + 0.8 * 0.2 * mach ** 2) - 273.15:.5f}"
    total = tmp_path / "tat.csv"
    with open(total, "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=list(rows[0]))
        w.writeheader()
        w.writerows(rows)
    a, b = tmp_path / "a.json", tmp_path / "b.json"
    assert main(["legs", str(EXAMPLE), "--json", str(a)]) == 0
    assert main(["legs", str(total), "--temp-recovery", "0.8", "--json", str(b)]) == 0
    head = next(ln for ln in capsys.readouterr().out.splitlines()
                if ln.startswith(f"Legs: {total}"))
    assert head.endswith("; OAT from tat_c, recovery factor 0.8, at each leg's true Mach")
    da, db = json.loads(a.read_text()), json.loads(b.read_text())
    assert db["temperature"] == "tat_c, recovery factor 0.8" and da["temperature"] == "oat_c"
    for pa, pb in zip(da["points"], db["points"]):
        assert pb["dv_kt"] == pytest.approx(pa["dv_kt"], abs=0.01)
        assert pb["wind_speed_kt"] == pytest.approx(pa["wind_speed_kt"], abs=0.005)
    ka, kb = (d["global"]["parameters"]["k1"]["value"] for d in (da, db))
    assert kb == pytest.approx(ka, abs=2e-4)
    assert np.isfinite(db["global"]["parameters"]["k1"]["value"])
