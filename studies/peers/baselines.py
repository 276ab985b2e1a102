"""Peer baselines: the autopilots' own in-flight airspeed calibrators, re-implemented.

Two recursive filters, written from the published descriptions of ArduPilot's ARSPD_AUTOCAL
(`studies.peers.ardupilot`) and of PX4's airspeed-selector wind estimator (`studies.peers.px4`).
They run sample by sample over a `Flight`, as the autopilots do, and return a `BaselineTrack`:
the estimate and the filter's own (stated) covariance over time, so they can be compared with
pitotcal's batch output-error estimate. This module holds what the two share.

Both learn a single scale factor between the measured and the true airspeed. In pitotcal terms
that is the `constant` pressure-error model, Δp/q_c = k1:

- ArduPilot: EAS = sqrt(ratio · q_ci) and state z = 1/sqrt(ratio), so
  ½ ρ0 ratio = 1/(1 − k1), i.e. k1 = 1 − 2 z² / ρ0.
- PX4: measured TAS = k · |v_gps − wind| (k is the filter's "TAS scale"; the CAS scale is
  s = 1/k, CAS = s · IAS), so k² = q_ci/q_c = 1 − k1.

Where the sources leave something open (or depend on other autopilot modules), the choice
made here is marked "guess" in the comments and in the README section of the peers study.
"""

from dataclasses import dataclass

import numpy as np

from pitotcal.core.errors import PitotcalError
from pitotcal.core.flight import Flight
from pitotcal.core.units import RHO0_KGM3, wind_polar
from pitotcal.io.resample import latest_index

__all__ = [
    "BaselineTrack",
    "ardupilot_ratio_from_k1",
    "causal_samples",
    "check_flight",
    "delta_v_kt_from_k1",
    "k1_from_ardupilot_ratio",
]


def k1_from_ardupilot_ratio(ratio):
    """Constant-model k1 from ArduPilot's ARSPD_RATIO: ½ ρ0 ratio = 1 / (1 − k1)."""
    return 1.0 - 2.0 / (RHO0_KGM3 * np.asarray(ratio, dtype=float))


def ardupilot_ratio_from_k1(k1):
    """ArduPilot's ARSPD_RATIO equivalent to the constant-model k1."""
    return 2.0 / (RHO0_KGM3 * (1.0 - np.asarray(k1, dtype=float)))


def delta_v_kt_from_k1(k1, vi_kt):
    """Airspeed correction ΔV = V_c − V_i (kt) of the constant model at indicated `vi_kt`.

    q_c = q_ci / (1 − k1) makes V_c = V_i / sqrt(1 − k1) at every speed.
    """
    return np.asarray(vi_kt, dtype=float) * (1.0 / np.sqrt(1.0 - np.asarray(k1, dtype=float)) - 1.0)


@dataclass(frozen=True)
class BaselineTrack:
    """Time history of a peer filter.

    Attributes
    ----------
    name : str
        `ardupilot` or `px4`.
    time_s : ndarray, shape (M,)
        Times of the filter updates, s (the flight's clock).
    wind_n_mps, wind_e_mps : ndarray, shape (M,)
        Wind vector (the way the air mass moves, TO), m/s.
    wind_var_n, wind_var_e : ndarray, shape (M,)
        The filter's variances of the two wind states, (m/s)^2.
    k1, k1_std : ndarray, shape (M,)
        The filter's scale state expressed as the constant-model k1, and its stated 1-sigma
        (first-order propagation of the scale-state variance).
    k1_validated : ndarray or None, shape (M,)
        PX4 only: the scale after its 12-course-bin validation (what PX4 would apply).
    state, covariance : ndarray, shapes (M, 3), (M, 3, 3)
        Raw filter state and covariance in the autopilot's own parameters.
    n_rejected : int
        Measurements the innovation gate rejected (PX4).
    n_resets : int
        Filter re-initialisations (PX4).
    """

    name: str
    time_s: np.ndarray
    wind_n_mps: np.ndarray
    wind_e_mps: np.ndarray
    wind_var_n: np.ndarray
    wind_var_e: np.ndarray
    k1: np.ndarray
    k1_std: np.ndarray
    state: np.ndarray
    covariance: np.ndarray
    k1_validated: np.ndarray | None = None
    n_rejected: int = 0
    n_resets: int = 0

    @property
    def wind_speed_mps(self):
        return np.hypot(self.wind_n_mps, self.wind_e_mps)

    @property
    def wind_from_deg(self):
        return wind_polar(self.wind_n_mps, self.wind_e_mps)[1]

    def index_at(self, t_s):
        """Index of the last update at or before `t_s` (−1 when there is none yet)."""
        index, valid = latest_index(self.time_s, [t_s])
        return int(index[0]) if valid[0] else -1

    def at(self, t_s, vi_kt=None):
        """The estimate available at time `t_s` as a dict (what the autopilot knew then).

        With `vi_kt`, also the airspeed correction ΔV at that indicated airspeed and its
        stated 2-sigma (kt).
        """
        i = self.index_at(t_s)
        if i < 0:
            raise PitotcalError(f"{self.name}: no filter update before t = {t_s:g} s")
        out = {
            "k1": float(self.k1[i]), "k1_2sigma": float(2.0 * self.k1_std[i]),
            "wind_n_mps": float(self.wind_n_mps[i]), "wind_e_mps": float(self.wind_e_mps[i]),
            "wind_n_2sigma_mps": float(2.0 * np.sqrt(self.wind_var_n[i])),
            "wind_e_2sigma_mps": float(2.0 * np.sqrt(self.wind_var_e[i])),
            "wind_speed_mps": float(self.wind_speed_mps[i]),
            "wind_from_deg": float(self.wind_from_deg[i]),
        }
        if self.k1_validated is not None:
            out["k1_validated"] = float(self.k1_validated[i])
        if vi_kt is not None:
            k1, s1 = self.k1[i], self.k1_std[i]
            out["dv_kt"] = float(delta_v_kt_from_k1(k1, vi_kt))
            # d(ΔV)/dk1 = V_i / (2 (1 − k1)^1.5)
            out["dv_2sigma_kt"] = float(2.0 * s1 * vi_kt / (2.0 * (1.0 - k1) ** 1.5))
        return out


def check_flight(flight, name):
    """Refuse anything but a `Flight` of at least two samples (`name`: the filter's)."""
    if not isinstance(flight, Flight):
        raise PitotcalError(f"{name}: flight must be a pitotcal.Flight, "
                            f"got {type(flight).__name__}", param="flight")
    if flight.n < 2:
        raise PitotcalError(f"{name}: flight has {flight.n} samples, need at least 2",
                            param="flight")


def causal_samples(flight, rate_hz):
    """Causal samples at `rate_hz`: the latest flight sample at or before each tick.

    An autopilot's scheduler reads the newest sensor values at each tick; no interpolation
    into the future. Returns (ticks, qci_pa >= 0, vn, ve, vd (zeros without), rho).
    """
    t = flight.time_s
    ticks = np.arange(t[0], t[-1] + 1e-9, 1.0 / rate_hz)
    idx, _ = latest_index(t, ticks + 1e-9)
    vd = flight.gps_vd_mps[idx] if flight.gps_vd_mps is not None else np.zeros(idx.size)
    return (ticks, np.maximum(flight.qci_pa[idx], 0.0), flight.gps_vn_mps[idx],
            flight.gps_ve_mps[idx], vd, flight.rho_kgm3[idx])
