"""The `monitor` study, lean: one flight in 0.5 m/s turbulence, clean and with the three
target faults; the table, the summary's false-alarm and detection keys, the figure."""

import pytest
from pitotcal.studies import run_study


def test_monitor_study_quick(tmp_path):
    summary = run_study("monitor", runs=1, out_dir=tmp_path, workers=0, quick=True)
    assert summary["n_failed"] == 0
    fa = summary["false_alarms"]["turb-0.5"]
    assert fa["flights"] == 1 and fa["hours"] == pytest.approx(210 / 3600)
    assert fa["by_design"]["0.02"]["alarms"] == 0
    det = summary["detection"]["turb-0.5"]
    assert det["blocked:0"]["detected"] == 1.0 and det["blocked:0"]["max_s"] <= 5.0
    assert det["leak:0.1"]["detected"] == 1.0 and det["leak:0.1"]["max_s"] <= 10.0
    assert det["blocked:0"]["kind_right"] == 1.0 and det["leak:0.1"]["kind_right"] == 1.0
    assert summary["targets"]["frozen"]["met"] and summary["targets"]["leak_10pct"]["met"]
    # the oracle, told the leak, finds it in the first block after the onset, like the monitor
    assert det["leak:0.1"]["oracle"]["max_s"] <= 1.0
    assert "oracle" not in det["blocked:0"]
    assert (tmp_path / "monitor.png").stat().st_size > 10_000


@pytest.mark.slow
def test_monitor_study_full_grid(tmp_path):
    summary = run_study("monitor", runs=2, out_dir=tmp_path, workers=2)
    assert summary["n_failed"] == 0 and set(summary["false_alarms"]) == {
        "calm", "turb-0.5", "turb-1.0", "wind-drift"}
