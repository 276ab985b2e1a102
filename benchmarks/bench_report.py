"""Benchmark of the calibration report and the autopilot parameter (issue 10).

Run: ``python benchmarks/bench_report.py [--repeats 5]``. In one process, medians of
`--repeats` runs of: the report of a result JSON alone (two figures, template); the report with
the flight and its fit (the paper-style figure and the track added); `result.plot()` to PNG (the
existing calibration figure, the baseline the report figures are compared with); and
`estimation.reporting.autopilot_params.recommend` (three fits) on a 16,000-sample synthetic flight.
"""

import argparse
import sys
from pathlib import Path

from timing import median_s

sys.path.insert(0, str(Path(__file__).resolve().parents[1] / "tests"))



def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=5)
    args = parser.parse_args()

    import io

    from pitotcal.estimation import identify
    from pitotcal.estimation.reporting.autopilot_params import recommend
    from pitotcal.estimation.reporting.calibration_report import build_report, render_html
    from synthetic import synthetic_flight

    flight, _ = synthetic_flight(seed=0, n=16000, model="constant", k=(0.18,),
                                 turbulence_mps=0.5, gps_rate_hz=5.0, gps_noise_mps=0.05)
    ident = identify(flight, model="inverse")
    doc = ident.to_dict()
    rows = [
        ("report, result JSON alone", lambda: render_html(build_report(doc))),
        ("report, with flight and fit",
         lambda: render_html(build_report(doc, flight=flight, ident=ident))),
        ("baseline: result.plot() to PNG", lambda: ident.plot().savefig(io.BytesIO(),
                                                                        format="png", dpi=100)),
        ("recommend ARSPD_RATIO (3 fits)", lambda: recommend(flight, "ArduPilot", 1.9936)),
    ]
    base = None
    print(f"| step (N = {flight.n}) | median s | / baseline |\n|---|---:|---:|")
    results = [(name, median_s(fun, args.repeats)) for name, fun in rows]
    base = dict(results)["baseline: result.plot() to PNG"]
    for name, sec in results:
        print(f"| {name} | {sec:.3f} | {sec / base:.2f} |")


if __name__ == "__main__":
    main()
