"""Benchmark of the live updates (issue 12: `identify --live` >= 1 Hz with <= 0.2 s per update
for a 16,000-sample maneuver; the monitor's update each second).

Run: ``python benchmarks/bench_live.py [--repeats 7] [--samples 16000]``. One live update of
`identify --live` is: the stream buffer turned into a Flight (`MavlinkFlightBuffer.flight`) and
`estimation.live.LiveIdentifier.update` on all of it, after an update on the record one second
shorter (so the solver for the new length is built, as live). Baselines in the same run: the
same update started cold (IPOPT from the linear least-squares start), and the full offline
`identify` (with trimming and the step test; what each update was before the warm start). One
monitor update is `LiveMonitor.update` on the record grown by one second. Prints a markdown
table of medians.
"""

import argparse
import statistics
import sys
import time
from pathlib import Path
from types import SimpleNamespace

from timing import median_s

ROOT = Path(__file__).resolve().parents[1]


def _flight(n, rate_hz=50.0):
    from pitotcal.maneuvers import simulate
    from pitotcal.studies.engine.common import get_plan

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



def _update_times(flight, grown, buf, repeats, warm):
    """Median seconds of one live update (buffer -> Flight + warm or cold fit) and of its
    parts (the solver's build for the new length, the IPOPT solve, the covariance), and its
    process CPU time (less moved by other work on the machine than the wall time)."""
    from pitotcal.estimation.live import LiveIdentifier

    total, cpu, parts = [], [], []
    for _ in range(repeats):
        live = LiveIdentifier("inverse")
        live.update(grown)
        start, start_cpu = time.perf_counter(), time.process_time()
        result = live.update(buf.flight(), warm=warm)
        total.append(time.perf_counter() - start)
        cpu.append(time.process_time() - start_cpu)
        parts.append(result.timing_s)
    parts = {k: statistics.median(p[k] for p in parts) for k in ("build", "solve", "covariance")}
    parts["cpu"] = statistics.median(cpu)
    return statistics.median(total), parts, result


def main():
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--samples", type=int, default=16000)
    args = parser.parse_args()
    from pitotcal.estimation import identify
    from pitotcal.estimation.monitor.monitoring import LiveMonitor
    from pitotcal.estimation.monitor.model import Calibration

    flight = _flight(args.samples)
    buf = _buffer(flight)
    grown = flight.window(None, flight.time_s[-1] - 1.0)
    offline = median_s(lambda: identify(flight), args.repeats)
    to_flight = median_s(buf.flight, args.repeats)
    cold, cold_parts, _ = _update_times(flight, grown, buf, args.repeats, warm=False)
    warm, warm_parts, last = _update_times(flight, grown, buf, args.repeats, warm=True)
    cal = Calibration.from_result(identify(flight))
    rate = 1.0 / float(flight.time_s[1] - flight.time_s[0])

    def monitor_update():
        mon = LiveMonitor(cal)
        mon.update(grown)
        start = time.perf_counter()
        mon.update(flight)
        return time.perf_counter() - start

    mon = statistics.median(monitor_update() for _ in range(args.repeats))
    print(f"| what ({flight.n} samples, {rate:g} Hz; medians of {args.repeats}) | median s |"
          f"\n|---|---:|")
    print(f"| offline identify (trimming, step test; each update before the warm start) | "
          f"{offline:.3f} |")
    print(f"| buffer -> Flight | {to_flight:.3f} |")
    for name, t, parts in (("cold", cold, cold_parts), ("warm", warm, warm_parts)):
        print(f"| identify --live update, {name} start (incl. buffer -> Flight) | {t:.3f} "
              f"({t / offline:.2f}x offline; build {parts['build']:.3f}, solve "
              f"{parts['solve']:.3f}, covariance {parts['covariance']:.3f}; process CPU "
              f"{parts['cpu']:.3f}) |")
    print(f"| warm / cold update | {warm / cold:.2f} (target <= 0.2 s per update: "
          f"{'met' if warm <= 0.2 else 'NOT met'}; last warm fit {last.iterations} iterations) |")
    print(f"| monitor live update (the newest 1 s, 2 blocks) | {mon:.4f} |")
    sys.stdout.flush()


if __name__ == "__main__":
    main()
