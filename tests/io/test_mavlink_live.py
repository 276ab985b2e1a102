"""A simulated flight sent as MAVLink over UDP on 127.0.0.1 (pymavlink): `monitor` and
`identify` on the stream give what they give on the file of the same samples; bad streams give
clear messages and keep what arrived."""

import numpy as np
import pytest
from mavsend import as_sent, free_udp_port, send_flight
from pitotcal.estimation import identify
from pitotcal.estimation.live import identify_stream, monitor_stream
from pitotcal.estimation.monitor.monitoring import monitor
from pitotcal.estimation.monitor.model import Calibration
from pitotcal.maneuvers import simulate
from pitotcal.maneuvers.fly.faults import Fault, apply_fault
from plans import circle_plan

from pitotcal.core.errors import FlightDataError, PitotcalError
from pitotcal.io.mavlink_live import FIRST_MESSAGE_TIMEOUT_S, MavlinkFlightBuffer, read_stream

# The monitor designs its tests before it listens (0.2-0.7 s on a loaded machine): UDP sent
# before that is lost, so its senders start later than the default 0.3 s.
MONITOR_DELAY_S = 1.5

pytest.importorskip("pymavlink")


@pytest.fixture(scope="module")
def flights():
    plan = circle_plan(duration_s=150.0)
    cal_flight, _ = simulate(plan, seed=100, rate_hz=10.0)
    flight, truth = simulate(plan, seed=4, rate_hz=10.0, keep_history=True)
    leak = apply_fault(flight, truth, Fault("leak", 90.0, 0.15))
    return Calibration.from_result(identify(cal_flight)), as_sent(leak)[0]


def test_monitor_stream_equals_file(flights):
    cal, flight = flights
    port = free_udp_port()
    send_flight(flight, port, delay_s=MONITOR_DELAY_S)
    live, buf = monitor_stream(f"udpin:127.0.0.1:{port}", cal, idle_timeout_s=1.0,
                               oat_k=None)
    assert buf.n == flight.n and buf.n_out_of_order == 0
    offline = monitor(flight, cal)
    assert len(live.alarms) == len(offline.alarms) == 1
    for key in ("start_s", "kind", "onset_s"):
        assert live.alarms[0][key] == offline.alarms[0][key]
    assert live.alarms[0]["size"] == pytest.approx(offline.alarms[0]["size"], rel=1e-6)


def test_identify_stream_equals_file(flights):
    _, flight = flights
    clean = flight.window(None, 89.0)       # before the leak
    port = free_udp_port()
    send_flight(clean, port)
    fixes = []
    # the simulated truth is q_c = ½ρV² (incompressible): both fitted as it was made
    result, got, _, _buf = identify_stream(f"udpin:127.0.0.1:{port}", idle_timeout_s=1.0,
                                          on_fix=lambda fix, msg: fixes.append(fix),
                                          air="incompressible")
    offline = identify(clean, air="incompressible")
    np.testing.assert_allclose(result.params, offline.params, rtol=1e-6, atol=1e-9)
    assert got.n == clean.n


def test_identify_stream_final_record_takes_identify_options(flights):
    """`record_options` (identify --live --wind / --wind-knot-s / --hides-threshold-kt): the
    final record is identify's with them, as offline; a bad one is refused before the stream
    opens."""
    _, flight = flights
    clean = flight.window(None, 89.0)
    options = {"wind": "drifting", "wind_knot_s": 40.0, "hides_threshold_kt": 0.5}
    with pytest.raises(PitotcalError, match="wind_knot_s"):
        identify_stream("udpin:127.0.0.1:1", record_options={"wind_knot_s": 1.0})
    port = free_udp_port()
    send_flight(clean, port)
    result, _, _, _ = identify_stream(f"udpin:127.0.0.1:{port}", idle_timeout_s=1.0,
                                      air="incompressible", record_options=options)
    offline = identify(clean, air="incompressible", **options)
    assert result.wind_model["kind"] == "drifting" and result.wind_model["knot_s"] == 40.0
    np.testing.assert_allclose(result.params, offline.params, rtol=1e-6, atol=1e-9)
    assert result.to_dict()["consistency"] == offline.to_dict()["consistency"]


def test_out_of_order_and_missing_streams():
    plan = circle_plan(duration_s=30.0)
    flight, _ = simulate(plan, seed=1, rate_hz=10.0)
    port = free_udp_port()
    order = np.arange(flight.n)
    order[100], order[101] = order[101], order[100]          # one swapped pair
    send_flight(flight, port, order=order)
    buf = read_stream(f"udpin:127.0.0.1:{port}", idle_timeout_s=1.0)
    assert buf.n_out_of_order == 1 and buf.n == flight.n - 1
    assert "1 out-of-order samples dropped" in " ".join(buf.warnings())
    for skip, what in (({"skip_gps": True}, "no GPS velocity"),
                       ({"skip_pressure": True}, "no airspeed")):
        port = free_udp_port()
        send_flight(flight.window(None, 3.0), port, **skip)
        buf = read_stream(f"udpin:127.0.0.1:{port}", idle_timeout_s=1.0)
        with pytest.raises(FlightDataError, match=what):
            buf.flight()


def test_nothing_arrives():
    buf = read_stream(f"udpin:127.0.0.1:{free_udp_port()}", first_timeout_s=0.5)
    with pytest.raises(FlightDataError, match=r"no airspeed \(SCALED_PRESSURE\) received"):
        buf.flight()
    assert isinstance(buf, MavlinkFlightBuffer)


def test_sitl_log_replayed_as_mavlink(shared_file, tmp_path, capsys):
    """The ArduPlane SITL DataFlash log, as pitotcal reads it, sent as SCALED_PRESSURE and
    GLOBAL_POSITION_INT: `identify --live` writes, the moment the stream stops, the
    identification of the same samples read from a file (a flight CSV of them)."""
    import json

    from pitotcal.cli import main
    from pitotcal.io import read_flight, write_flight_csv

    with pytest.warns(UserWarning):
        log = read_flight(shared_file("ardupilot/arduplane_sitl.log"))
    sent = as_sent(log)[0]
    csv = write_flight_csv(sent, tmp_path / "sitl.csv")
    assert main(["identify", str(csv), "--json", str(tmp_path / "file.json")]) == 0
    port = free_udp_port()
    send_flight(sent, port)
    assert main(["identify", "--live", f"udpin:127.0.0.1:{port}", "--idle-s", "1", "--json",
                 str(tmp_path / "live.json")]) == 0
    live = json.loads((tmp_path / "live.json").read_text())
    offline = json.loads((tmp_path / "file.json").read_text())
    assert live["live"]["stream_ended"] == "idle" and live["n_samples"] == sent.n
    assert live["live"]["updates"] >= 1
    for name, p in offline["parameters"].items():
        assert live["parameters"][name]["value"] == pytest.approx(p["value"], rel=1e-5,
                                                                  abs=1e-6), name
        assert live["parameters"][name]["std"] == pytest.approx(p["std"], rel=1e-4), name
    assert "dV at" in capsys.readouterr().err        # the live updates
    # and `monitor` against that calibration: the stream's alarms are the file's
    codes = []
    for name, source in (("file", str(csv)), ("live", None)):
        if source is None:
            port = free_udp_port()
            send_flight(sent, port, delay_s=MONITOR_DELAY_S)
            source = f"udpin:127.0.0.1:{port}"
        codes.append(main(["monitor", source, "--calibration", str(tmp_path / "file.json"),
                           "--idle-s", "1", "--json", str(tmp_path / f"{name}.mon.json")]))
    mons = [json.loads((tmp_path / f"{n}.mon.json").read_text()) for n in ("file", "live")]
    assert codes[0] == codes[1] and len(mons[0]["alarms"]) == len(mons[1]["alarms"])
    for a, b in zip(mons[0]["alarms"], mons[1]["alarms"]):    # the CSV rounds to 9 digits
        assert a == {**b, "size": pytest.approx(b["size"], rel=1e-4)}
    assert mons[0]["n_samples"] == mons[1]["n_samples"] == sent.n


def test_monitor_cli_on_a_stream(flights, tmp_path, capsys):
    import json

    from pitotcal.cli import main
    from pitotcal.io.jsonfile import write_json

    cal, flight = flights
    cal_json = tmp_path / "cal.json"
    write_json(cal_json, {"model": cal.model, "parameters": {
        "k1": {"value": cal.k[0]}, "k2": {"value": cal.k[1]},
        "wind_speed_mps": {"value": float(np.hypot(cal.wind_n_mps, cal.wind_e_mps))},
        "wind_from_deg": {"value": float(np.degrees(np.arctan2(-cal.wind_e_mps,
                                                                -cal.wind_n_mps)) % 360)}},
        "noise_model": cal.noise})
    port = free_udp_port()
    send_flight(flight, port, delay_s=MONITOR_DELAY_S)
    code = main(["monitor", f"udpin:127.0.0.1:{port}", "--calibration", str(cal_json),
                 "--idle-s", "1"])
    out, err = capsys.readouterr()
    alarms = json.loads(out.splitlines()[-1])["alarms"]
    assert code == 1 and len(alarms) == 1 and alarms[0]["kind"] == "step"
    assert alarms[0]["start_s"] == monitor(flight, cal).alarms[0]["start_s"]
    assert "samples  q_ci" in err          # the live status line
    # the first line says where it listens, at once (not after the first message's wait)
    assert err.splitlines()[0] == (
        f"pitotcal monitor: listening on udpin:127.0.0.1:{port} for MAVLink (up to "
        f"{FIRST_MESSAGE_TIMEOUT_S:g} s for the first message, then ends after 1 s without "
        "one, or on Ctrl-C)")


def test_identify_live_says_where_it_listens_first(flights, tmp_path, capsys):
    from pitotcal.cli import main

    _, flight = flights
    port = free_udp_port()
    send_flight(flight.window(None, 60.0), port)
    assert main(["identify", "--live", f"udp:127.0.0.1:{port}", "--idle-s", "1",
                 "--air", "incompressible"]) == 0
    err = capsys.readouterr().err.splitlines()
    assert err[0].startswith(f"pitotcal identify: listening on udp:127.0.0.1:{port} for "
                             f"MAVLink (up to {FIRST_MESSAGE_TIMEOUT_S:g} s")
    assert any("dV at" in line for line in err[1:])


def test_live_record_has_the_offline_keys(flights, tmp_path, capsys):
    """`identify --live --json` writes the library's record, as offline (noise model, GPS-error
    statement, reading, budget), plus how the stream went; `monitor` reads it without falling
    back to an assumed noise model."""
    import json

    from pitotcal.cli import main
    from pitotcal.io import write_flight_csv
    from pitotcal.io.result_record import read_result

    _, flight = flights
    clean = flight.window(None, 89.0)       # before the leak
    csv = write_flight_csv(clean, tmp_path / "clean.csv")
    assert main(["identify", str(csv), "--json", str(tmp_path / "file.json")]) == 0
    port = free_udp_port()
    send_flight(clean, port)
    assert main(["identify", "--live", f"udpin:127.0.0.1:{port}", "--idle-s", "1", "--json",
                 str(tmp_path / "live.json")]) == 0
    capsys.readouterr()
    offline = json.loads((tmp_path / "file.json").read_text())
    live = json.loads((tmp_path / "live.json").read_text())
    assert set(live) == set(offline) | {"live"}
    assert {"noise_model", "gps_error", "reading", "uncertainty_budget"} <= set(live)
    for section in ("noise_model", "gps_error", "reading"):
        assert set(live[section]) == set(offline[section]), section
    assert set(live["airspeed_correction"][0]) == set(offline["airspeed_correction"][0])
    assert live["parameters"]["k1"]["value"] == pytest.approx(
        offline["parameters"]["k1"]["value"], rel=1e-4)
    cal = Calibration.from_dict(read_result(tmp_path / "live.json"), source="live.json")
    assert cal.notes == () and "fallback" not in cal.noise
    assert cal.noise["n_blocks"] == live["noise_model"]["n_blocks"] > 100
