"""Pitot-static faults for the simulator: the sensor record of a simulated flight, spoiled.

A fault post-processes what `maneuvers.fly.simulator.simulate(..., keep_history=True)` returned: the
fault-free measured q_ci is rebuilt from the truth (the true q_c through the true pressure-error
model), the transducer noise the record carried (recorded minus fault-free) is kept, and the
fault acts on the fault-free signal from its onset on. The aircraft flies on as planned (the
autopilot is not fooled): what a monitor sees is the pneumatic failure alone, with its truth.

Kinds (`FAULT_KINDS`) and what `size` means:

``blocked``  total port blocked, q_ci = trapped total minus the current static pressure; `size`
             is the drain time constant, s (0: sealed, q_ci frozen in level flight; > 0: the
             trapped pressure drains to the static through the drain hole, q_ci -> 0).
``static``   static port blocked: the static pressure stays trapped (relaxing to the true one
             with time constant `size`, s; 0 sealed); q_ci = q_ci + p_s - p_s,trapped and the
             density made from it is wrong. Invisible in level flight, like the real one.
``leak``     a leak in the total line: q_ci scaled by (1 - size) from the onset (0.1: 10 % low).
``icing``    an icing ramp: the indicated airspeed falls by `size` kt per minute from the onset
             (q_ci = ½ρ0 V_i², clipped at 0).
``water``    water in the lines: q_ci multiplied by (1 - size·|u(t)|), u a unit-RMS random
             signal low-passed at 1 Hz (erratic and low); `size` is a fraction of q_ci.
"""

from dataclasses import asdict, dataclass

import numpy as np

from pitotcal.core.checks import choice, number
from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import get_model, qci_from_qc_pa
from pitotcal.core.units import RHO0_KGM3, isa_pressure_pa, kt_to_mps

__all__ = ["FAULT_KINDS", "FAULT_UNITS", "Fault", "apply_fault", "parse_fault", "truth_with_fault"]

FAULT_KINDS = ("blocked", "static", "leak", "icing", "water")
FAULT_UNITS = {"blocked": "s", "static": "s", "leak": "fraction", "icing": "kt/min",
               "water": "fraction"}
_WATER_BAND_HZ = 1.0


@dataclass(frozen=True)
class Fault:
    """One pitot-static fault: `kind` (FAULT_KINDS), `onset_s` (time in the record, s) and
    `size` (unit in FAULT_UNITS[kind]); `seed` drives the random part of ``water``."""

    kind: str
    onset_s: float
    size: float
    seed: int = 0

    def to_dict(self):
        """As written in the truth JSON's ``"fault"``, with the unit of `size`."""
        return {**asdict(self), "size_unit": FAULT_UNITS[self.kind]}


def check_fault(kind, onset_s, size, seed=0):
    """A checked `Fault` (each value named like its parameter)."""
    kind = choice("fault kind", kind, FAULT_KINDS)
    onset_s = number("fault onset_s", onset_s)
    hi = 0.95 if kind in ("leak", "water") else np.inf
    size = number("fault size", size, 0.0, hi)
    return Fault(kind, onset_s, size, int(seed))


def parse_fault(text, seed=0):
    """A `Fault` from ``KIND:ONSET_S:SIZE`` (the `simulate --fault` option), e.g. ``leak:120:0.1``."""
    parts = str(text).split(":")
    if len(parts) != 3:
        raise PitotcalError(f"fault {text!r} must be KIND:ONSET_S:SIZE with KIND one of "
                            f"{', '.join(FAULT_KINDS)} (e.g. leak:120:0.1)", param="fault")
    try:
        onset, size = float(parts[1]), float(parts[2])
    except ValueError:
        raise PitotcalError(f"fault {text!r}: ONSET_S and SIZE must be numbers",
                            param="fault") from None
    try:
        return check_fault(parts[0], onset, size, seed)
    except PitotcalError as exc:        # the option's own text, as the user wrote it
        raise PitotcalError(f"fault {text!r}: {exc}",
                            param="fault") from None


def apply_fault(flight, truth, fault):
    """The flight as recorded with `fault`; the samples before the onset are unchanged.

    Parameters
    ----------
    flight : pitotcal.core.flight.Flight
        From `simulate(..., keep_history=True)`.
    truth : maneuvers.fly.truth.Truth
        Its truth, with the history (the true q_c and altitude).
    fault : Fault

    Returns
    -------
    pitotcal.core.flight.Flight
        The same flight with q_ci (and for ``static`` the density) spoiled; its `meta` gains
        ``fault`` (``KIND:ONSET_S:SIZE``).
    """
    from dataclasses import replace

    if not isinstance(fault, Fault):
        raise PitotcalError(f"fault must be a Fault (parse_fault), got {type(fault).__name__}")
    if truth.history is None:
        raise PitotcalError("apply_fault needs the truth's history: simulate(..., "
                            "keep_history=True)")
    t = flight.time_s
    if fault.onset_s >= t[-1]:
        raise PitotcalError(f"fault onset {fault.onset_s:g} s is at or after the flight's end "
                            f"({t[-1]:.1f} s): it would never happen", param="fault")
    clean = qci_from_qc_pa(get_model(truth.model), truth.k, truth.history["qc_pa"])
    noise = flight.qci_pa - clean
    after = t >= fault.onset_s
    age = np.where(after, t - fault.onset_s, 0.0)
    alt = truth.history["alt_m"]
    rho = flight.rho_kgm3
    spoiled = _SPOILERS[fault.kind](clean, t, age, after, alt, fault)
    if fault.kind == "static":
        spoiled, ps_ratio = spoiled
        rho = np.where(after, rho * ps_ratio, rho)
    qci = np.where(after, spoiled + noise, flight.qci_pa)
    meta = {**flight.meta, "fault": f"{fault.kind}:{fault.onset_s:g}:{fault.size:g}"}
    return replace(flight, qci_pa=qci, rho_kgm3=rho, meta=meta)


def truth_with_fault(truth, fault):
    """The truth JSON's content with ``"fault"`` (`Fault.to_dict`) added."""
    return {**truth.to_dict(), "fault": fault.to_dict()}


def _onset_index(after):
    return int(np.argmax(after)) if after.any() else after.size - 1


def _blocked(clean, t, age, after, alt, fault):
    # trapped total pressure p_t0 = q_ci0 + p_s0; the transducer reads p_t - p_s(t)
    i0 = _onset_index(after)
    ps = isa_pressure_pa(alt)
    held = clean[i0] + ps[i0] - ps
    if fault.size > 0:   # the trapped total relaxes to the static through the drain hole
        held = held * np.exp(-age / fault.size)
    return held


def _static(clean, t, age, after, alt, fault):
    i0 = _onset_index(after)
    ps = isa_pressure_pa(alt)
    trapped = ps + (ps[i0] - ps) * (np.exp(-age / fault.size) if fault.size > 0 else 1.0)
    return clean + ps - trapped, trapped / ps


def _leak(clean, t, age, after, alt, fault):
    return clean * (1.0 - fault.size)


def _icing(clean, t, age, after, alt, fault):
    vi = np.sqrt(2.0 * np.maximum(clean, 0.0) / RHO0_KGM3)
    vi = np.maximum(vi - kt_to_mps(fault.size) * age / 60.0, 0.0)
    return 0.5 * RHO0_KGM3 * vi ** 2


def _water(clean, t, age, after, alt, fault):
    from .sensors import first_order_lag

    dt = float(np.median(np.diff(t))) if t.size > 1 else 1.0
    rng = np.random.default_rng(fault.seed)
    u = first_order_lag(rng.standard_normal(t.size), dt, 1.0 / (2 * np.pi * _WATER_BAND_HZ))
    u = u / max(float(np.std(u)), 1e-12)
    return clean * (1.0 - fault.size * np.abs(u))


_SPOILERS = {"blocked": _blocked, "static": _static, "leak": _leak, "icing": _icing,
             "water": _water}
