"""Benchmark of the live updates (issue 12: `identify --live` >= 1 Hz with <= 0.2 s per update
for a 16,000-sample maneuver; the monitor's update each second).

Run: ``python benchmarks/bench_live.py [--repeats 7] [--samples 16000]``. One live update of
`identify --live` is: the stream buffer turned into a Flight (`MavlinkFlightBuffer.flight`) and
`identify` on all of it. One monitor update is `LiveMonitor.update` on the record grown by one
second. Baseline in the same run: the offline `identify` on the same Flight (the update's ratio
to it shows the live overhead). Prints a markdown table of medians.
"""

import argparse
import statistics
import sys
import time
from pathlib import Path
from types import SimpleNamespace

ROOT = Path(__file__).resolve().parents[1]


def _flight(n, rate_hz=50.0):
    from pitotcal.maneuvers import simulate
    from pitotcal.studies.common import get_plan

    plan = get_plan(duration_s=n / rate_hz)
    return simulate(plan, seed=1, rate_hz=rate_hz)[0]


def _buffer(flight):
    """A stream buffer holding `flight` as MAVLink messages would have filled it."""
    from pitotcal.core.units import R_AIR_JKGK, isa_pressure_pa
    from pitotcal.io.mavlink_live import MavlinkFlightBuffer

    buf = MavlinkFlightBuffer("bench")
    ps = isa_pressure_pa(flight.alt_m)
    temp_k = ps / (R_AIR_JKGK * flight.rho_kgm3)
    for i in range(flight.n):
        buf.add(SimpleNamespace(get_type=lambda: "GLOBAL_POSITION_INT",
                                vx=flight.gps_vn_mps[i] * 100, vy=flight.gps_ve_mps[i] * 100,
                                vz=flight.gps_vd_mps[i] * 100, alt=flight.alt_m[i] * 1000))
        buf.add(SimpleNamespace(get_type=lambda: "SCALED_PRESSURE",
                                time_boot_ms=flight.time_s[i] * 1000,
                                press_diff=flight.qci_pa[i] / 100, press_abs=ps[i] / 100,
                                temperature=(temp_k[i] - 273.15) * 100))
    return buf


def _median(fun, repeats):
    times = []
    for _ in range(repeats):
        start = time.perf_counter()
        fun()
        times.append(time.perf_counter() - start)
    return statistics.median(times)


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--samples", type=int, default=16000)
    args = parser.parse_args()
    from pitotcal.estimation import identify
    from pitotcal.estimation.monitor import LiveMonitor
    from pitotcal.estimation.monitor_model import Calibration

    flight = _flight(args.samples)
    buf = _buffer(flight)
    offline = _median(lambda: identify(flight), args.repeats)
    live = _median(lambda: identify(buf.flight()), args.repeats)
    cal = Calibration.from_result(identify(flight))
    rate = 1.0 / float(flight.time_s[1] - flight.time_s[0])
    grown = flight.window(None, flight.time_s[-1] - 1.0)

    def monitor_update():
        mon = LiveMonitor(cal)
        mon.update(grown)
        start = time.perf_counter()
        mon.update(flight)
        return time.perf_counter() - start

    mon = statistics.median(monitor_update() for _ in range(args.repeats))
    print(f"| what ({flight.n} samples, {rate:g} Hz) | median s |\n|---|---:|")
    print(f"| offline identify (baseline) | {offline:.3f} |")
    print(f"| identify --live update: buffer -> Flight + identify | {live:.3f} "
          f"({live / offline:.2f}x baseline; target <= 0.2 s) |")
    print(f"| monitor live update (the newest 1 s, 2 blocks) | {mon:.4f} |")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
