"""`real-alfa`: the real ALFA Carbon-Z ArduPlane flight against the autopilot's own numbers.

Data: CMU AirLab ALFA dataset, flight carbonZ_2018-07-18-15-53-31 (engine failure), MAVLink
messages decoded to CSV, read where they are (`--data DIR`, ``$PITOTCAL_ALFA_DATA`` or
``./alfa-carbonz``; never copied) by `pitotcal.io.alfa`, whose docstring gives the reader's
choices (clock, density, segment). The study calibrates the powered segment with pitotcal
(constant and inverse models), runs the two peer filters (`studies.peers.ardupilot`,
`studies.peers.px4`) on the same data, and compares everything with what the autopilot itself
logged: its airspeed ratio (AIRSPEED_AUTOCAL.ratio) and its wind (WIND).

One run, in process: the table (``real-alfa.csv``) has one row per method, the tracks of the
filters and the autopilot over time go to ``real-alfa_tracks.csv``, the figure to
``real-alfa.png``.
"""

import csv
import logging
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from pitotcal.core.checks import wrap_deg
from pitotcal.core.errors import PitotcalError
from pitotcal.core.units import incompressible_cas_mps, mps_to_kt, wind_polar
from pitotcal.io.alfa import find_alfa_data, read_alfa_csv, read_alfa_flight
from pitotcal.io.atomic import atomic_open

from ..peers.baselines import ardupilot_ratio_from_k1, k1_from_ardupilot_ratio
from ..peers.ardupilot import ardupilot_autocal
from ..peers.px4 import px4_wind_estimator
from .figure import plot_real_flight
from ..engine.runner import RunsInterrupted
from ..engine.study import Collected

__all__ = ["STUDY", "RealAlfaStudy", "RealFlightAnalysis", "analyse_real_flight"]

log = logging.getLogger(__name__)

NAME = "real-alfa"
MODELS = ("constant", "inverse")


@dataclass(frozen=True)
class RealFlightAnalysis:
    """What `analyse_real_flight` found: the `summary` (JSON-ready) and, for the figure and the
    tracks file, the peer filters' `BaselineTrack`s, the autopilot's logged tracks
    (`autopilot`: ratio and wind over time) and the powered `segment_s` (start, end)."""

    summary: dict
    ardupilot: object
    px4: object
    autopilot: dict
    segment_s: tuple


def analyse_real_flight(data_dir, oat="autopilot"):
    """Calibrate the ALFA flight in `data_dir` and compare with the autopilot and the peers.

    Returns
    -------
    RealFlightAnalysis
        Its summary: the segment, pitotcal's constant and inverse estimates with 2σ, the
        equivalent ArduPilot ratio, the autopilot's ratio and wind over the segment, the peer
        filters' final estimates, the comparison verdicts and (with the autopilot's density)
        k1 under the ISA temperature instead.
    """
    d = Path(data_dir)
    flight = read_alfa_flight(d, oat=oat)
    seg = (float(flight.time_s[0]), float(flight.time_s[-1]))
    vi_kt = mps_to_kt(incompressible_cas_mps(flight.qci_pa))
    vi_ref_kt = float(np.median(vi_kt))
    ours = {model: _calibrate(flight, model, vi_ref_kt) for model in MODELS}
    ap = _autopilot_tracks(d, float(flight.meta["t0_unix_s"]))
    autopilot = _autopilot_summary(ap, seg)
    ardu = ardupilot_autocal(flight, initial_ratio=autopilot["ratio"])
    px4 = px4_wind_estimator(flight)
    summary = {
        "study": NAME, "data": str(d), "segment_s": list(seg),
        "failure_time_s": float(flight.meta.get("failure_time_s", "nan")),
        "n_samples": int(flight.n), "density": flight.meta.get("density"),
        "median_vi_kt": vi_ref_kt, "vi_range_kt": [float(np.min(vi_kt)), float(np.max(vi_kt))],
        "pitotcal": ours, "autopilot": autopilot,
        "peers": {tr.name: _peer_summary(tr, seg[1], vi_ref_kt) for tr in (ardu, px4)},
        "comparison": _compare(ours["constant"], autopilot),
    }
    if oat == "autopilot":
        summary.update(_isa_sensitivity(d))
    return RealFlightAnalysis(summary, ardu, px4, ap, seg)


def _calibrate(flight, model, vi_ref_kt):
    """pitotcal's estimate of one model structure: every parameter with its 2σ, ΔV at the
    median V_i, and for `constant` the equivalent ArduPilot ratio."""
    from pitotcal.estimation import identify

    res = identify(flight, model=model)
    dv, dv2 = res.delta_v_kt(vi_ref_kt)
    entry = {name: {"value": float(v), "2sigma": float(2.0 * s)}
             for name, v, s in zip(res.param_names, res.params, res.std)}
    entry.update(converged=bool(res.success), warnings=list(res.warnings),
                 n_samples=int(res.n_samples), noise_std_pa=float(res.noise_std_pa),
                 dv_at_median_vi_kt={"value": float(dv), "2sigma": float(dv2)})
    if model == "constant":
        k1, s1 = res.value("k1"), res.stddev("k1")
        ratio = float(ardupilot_ratio_from_k1(k1))
        entry["ardupilot_ratio_equivalent"] = {
            "value": ratio, "2sigma": float(2.0 * s1 * ratio / (1.0 - k1))}
    return entry


def _autopilot_tracks(d, t0):
    """The autopilot's logged ratio and wind over time (the flight's clock)."""
    cal = read_alfa_csv(d / "airspeed_autocal.csv")
    wind = read_alfa_csv(d / "wind.csv")
    return {
        "ratio_t": cal["time_unix_s"] - t0, "ratio": cal["ratio"],
        "autocal_state_moved": bool(np.ptp(cal.get("state_x", np.zeros(1))) > 0
                                    or np.ptp(cal.get("Pax", np.zeros(1))) > 0),
        "wind_t": wind["time_unix_s"] - t0, "wind_speed": wind["speed"],
        # WIND.direction is where the wind blows FROM, in (-180, 180]
        "wind_from": wind["direction"] % 360.0,
    }


def _mean_wind(speed, from_deg):
    """Mean wind vector of a FROM-convention track as (speed m/s, from deg)."""
    wn = -np.mean(speed * np.cos(np.radians(from_deg)))
    we = -np.mean(speed * np.sin(np.radians(from_deg)))
    return float(np.hypot(wn, we)), float(wind_polar(wn, we)[1])


def _autopilot_summary(ap, seg):
    """The autopilot's ratio (median) and mean wind over the segment, and over its second half:
    its wind starts far off (7.9 m/s) and settles."""
    in_seg = (ap["ratio_t"] >= seg[0]) & (ap["ratio_t"] <= seg[1])
    ratio = float(np.median(ap["ratio"][in_seg]))
    w_seg = (ap["wind_t"] >= seg[0]) & (ap["wind_t"] <= seg[1])
    speed, from_deg = ap["wind_speed"][w_seg], ap["wind_from"][w_seg]
    late = ap["wind_t"][w_seg] >= 0.5 * (seg[0] + seg[1])
    mean_speed, mean_from = _mean_wind(speed, from_deg)
    late_speed, late_from = _mean_wind(speed[late], from_deg[late])
    return {"ratio": ratio, "k1_equivalent": float(k1_from_ardupilot_ratio(ratio)),
            "autocal_learning": ap["autocal_state_moved"],
            "wind_mean_speed_mps": mean_speed, "wind_mean_from_deg": mean_from,
            "wind_second_half_speed_mps": late_speed, "wind_second_half_from_deg": late_from,
            "wind_speed_range_mps": [float(speed.min()), float(speed.max())]}


def _peer_summary(track, t_end_s, vi_ref_kt):
    """A peer filter's estimate at the end of the segment."""
    last = track.at(t_end_s, vi_kt=vi_ref_kt)
    return {"k1": last["k1"], "k1_2sigma": last["k1_2sigma"],
            "ardupilot_ratio_equivalent": float(ardupilot_ratio_from_k1(last["k1"])),
            "wind_speed_mps": last["wind_speed_mps"], "wind_from_deg": last["wind_from_deg"],
            **({"k1_validated": last["k1_validated"]} if "k1_validated" in last else {})}


def _compare(const, ap):
    """pitotcal's constant model against the autopilot's ratio and (settled) wind."""
    k1, ws, wf = const["k1"], const["wind_speed_mps"], const["wind_from_deg"]
    dk1 = k1["value"] - ap["k1_equivalent"]
    late_dir = float(wrap_deg(wf["value"] - ap["wind_second_half_from_deg"]))
    return {
        "k1_difference": dk1,
        "k1_difference_in_2sigma": dk1 / max(k1["2sigma"], 1e-12),
        "autopilot_ratio_within_our_2sigma": bool(abs(dk1) <= k1["2sigma"]),
        "wind_speed_difference_mps": ws["value"] - ap["wind_mean_speed_mps"],
        "wind_from_difference_deg": float(wrap_deg(wf["value"] - ap["wind_mean_from_deg"])),
        "wind_speed_difference_late_mps": ws["value"] - ap["wind_second_half_speed_mps"],
        "wind_from_difference_late_deg": late_dir,
        "autopilot_late_wind_within_our_2sigma": bool(
            abs(ws["value"] - ap["wind_second_half_speed_mps"]) <= ws["2sigma"]
            and abs(late_dir) <= wf["2sigma"]),
        "autopilot_wind_speed_range_mps": ap["wind_speed_range_mps"],
        "ias_error_of_autopilot_ratio_pct": float(
            100.0 * (np.sqrt(ap["ratio"] / float(ardupilot_ratio_from_k1(k1["value"]))) - 1.0)),
    }


def _isa_sensitivity(d):
    """k1 of the constant model with the ISA temperature instead of the autopilot's density
    (the largest systematic of this flight); nothing when that run fails."""
    from pitotcal.estimation import identify

    try:
        isa = identify(read_alfa_flight(d, oat="isa"), model="constant")
    except PitotcalError as exc:          # keep the main result
        log.warning("ISA sensitivity run failed: %s", exc)
        return {}
    return {"k1_constant_with_isa_oat": {"value": isa.value("k1"),
                                         "2sigma": 2.0 * isa.stddev("k1")}}


def table_rows(summary):
    """real-alfa.csv: one row per method (pitotcal's two models, the peers at the end of the
    segment, the autopilot's log)."""
    rows = []
    for model in MODELS:
        e = summary["pitotcal"][model]
        k2 = e.get("k2", {"value": "", "2sigma": ""})
        ratio = e["ardupilot_ratio_equivalent"]["value"] if model == "constant" else ""
        rows.append(_row("pitotcal", model, e["k1"]["value"], e["k1"]["2sigma"], k2["value"],
                         k2["2sigma"], ratio, e["wind_speed_mps"]["value"],
                         e["wind_speed_mps"]["2sigma"], e["wind_from_deg"]["value"],
                         e["wind_from_deg"]["2sigma"]))
    for name, p in summary["peers"].items():
        rows.append(_row(f"{name}-style filter (end of segment)", "constant", p["k1"],
                         p["k1_2sigma"], "", "", p["ardupilot_ratio_equivalent"],
                         p["wind_speed_mps"], "", p["wind_from_deg"], ""))
    a = summary["autopilot"]
    rows.append(_row("autopilot log (ARSPD ratio, mean WIND)", "constant", a["k1_equivalent"],
                     "", "", "", a["ratio"], a["wind_mean_speed_mps"], "",
                     a["wind_mean_from_deg"], ""))
    return rows


TABLE_COLUMNS = ("method", "model", "k1", "k1_2sigma", "k2", "k2_2sigma", "ardupilot_ratio",
                 "wind_speed_mps", "wind_speed_2sigma_mps", "wind_from_deg",
                 "wind_from_2sigma_deg")


def _row(*values):
    return {c: float(v) if isinstance(v, float) else v for c, v in zip(TABLE_COLUMNS, values)}


def _write_tracks(path, ardu, px4, ap):
    """real-alfa_tracks.csv: the peers' estimates and the autopilot's log over time."""
    with atomic_open(path, "w", newline="") as fh:
        w = csv.writer(fh)
        w.writerow(["source", "time_s", "k1", "k1_2sigma", "wind_speed_mps", "wind_from_deg"])
        for tr in (ardu, px4):
            for i in range(tr.time_s.size):
                w.writerow([tr.name, f"{tr.time_s[i]:.2f}", f"{tr.k1[i]:.6g}",
                            f"{2 * tr.k1_std[i]:.6g}", f"{tr.wind_speed_mps[i]:.4f}",
                            f"{tr.wind_from_deg[i]:.2f}"])
        for t, r in zip(ap["ratio_t"], ap["ratio"]):
            w.writerow(["autopilot_ratio", f"{t:.2f}", f"{k1_from_ardupilot_ratio(r):.6g}", "",
                        "", ""])
        for t, sp, fr in zip(ap["wind_t"], ap["wind_speed"], ap["wind_from"]):
            w.writerow(["autopilot_wind", f"{t:.2f}", "", "", f"{sp:.4f}", f"{fr:.2f}"])
    return path


@dataclass(frozen=True)
class RealAlfaStudy:
    """The `real-alfa` study: one run on the real flight (`studies.engine.study.Study`)."""

    name: str = NAME
    description: str = ("the real ALFA Carbon-Z ArduPlane flight: pitotcal vs the autopilot's "
                        "ratio and wind and the peer filters")
    oat: str = "autopilot"

    def collect(self, settings):
        if settings.runs not in (None, 1):
            raise PitotcalError(f"runs must be 1 for {NAME} (one real flight), got "
                                f"{settings.runs}", param="runs")
        folder = find_alfa_data(settings.data_dir)
        try:
            analysis = analyse_real_flight(folder, oat=self.oat)
        except KeyboardInterrupt:
            raise RunsInterrupted([], 0, 1) from None
        if settings.progress is not None:
            settings.progress(1, 1)
        return Collected(table_rows(analysis.summary), 1, details=analysis,
                         columns=TABLE_COLUMNS)

    def report(self, collected, out_dir):
        a = collected.details
        out = Path(out_dir)
        tracks = _write_tracks(out / f"{NAME}_tracks.csv", a.ardupilot, a.px4, a.autopilot)
        figure = plot_real_flight(out / f"{NAME}.png", a.summary, a.ardupilot, a.px4,
                                  a.autopilot, a.segment_s)
        return a.summary, [tracks, figure]

    def headline(self, summary):
        """The result in one line: k1 and the wind against what the autopilot flew with."""
        c, ap = summary["pitotcal"]["constant"], summary["autopilot"]
        ratio, ws, wf = c["ardupilot_ratio_equivalent"], c["wind_speed_mps"], c["wind_from_deg"]
        return (f"k1 = {c['k1']['value']:.3f} ± {c['k1']['2sigma']:.3f} (2σ), ArduPilot ratio "
                f"{ratio['value']:.2f} ± {ratio['2sigma']:.2f} (the autopilot flew "
                f"{ap['ratio']:.3f}); wind {ws['value']:.1f} ± {ws['2sigma']:.1f} m/s from "
                f"{wf['value']:.0f} ± {wf['2sigma']:.0f}° (the autopilot's, settled: "
                f"{ap['wind_second_half_speed_mps']:.1f} m/s from "
                f"{ap['wind_second_half_from_deg']:.0f}°)")

    def repeat(self, settings, run_index):
        if run_index != 0:
            raise PitotcalError(f"run index {run_index} is outside 0..0 ({NAME} is one run)",
                                param="run_index")
        return self.collect(settings).rows


STUDY = RealAlfaStudy()
