"""`Flight`: one calibration flight's samples, SI units (the flight CSV's content, docs/interfaces.md)."""

from dataclasses import dataclass, field, replace

import numpy as np

__all__ = ["MIN_TRACK_SPREAD_DEG", "Flight", "track_spread_deg"]

# Wind and calibration separate only if the track turns: up to half a circle (an out-and-back
# line included) the wind across the track is indistinguishable from a scale error.
MIN_TRACK_SPREAD_DEG = 180.0


@dataclass(frozen=True)
class Flight:
    """One calibration flight, SI units, all arrays of shape (N,).

    Attributes
    ----------
    time_s : ndarray
        Sample times, s, strictly increasing (gaps are allowed).
    qci_pa : ndarray
        Measured impact pressure q_ci, Pa, > 0.
    gps_vn_mps, gps_ve_mps : ndarray
        GPS ground velocity north / east, m/s.
    rho_kgm3 : ndarray
        Air density, kg/m^3 (given, or ps / (R T)).
    gps_vd_mps : ndarray or None
        GPS velocity down, m/s; when present it enters the true-airspeed magnitude.
    alt_m : ndarray or None
        Altitude, m (for plots and checks only; NaN where the file had no usable value).
    ps_pa : ndarray or None
        Static pressure as the aircraft's static source reads it, Pa (p_s + Δp_p when the
        static port has a position error). With `oat_k` it makes the compressible
        calibration possible (`pitotcal.estimation.identify`, air="compressible").
    oat_k : ndarray or None
        Static (outside) air temperature, K.
    ps_ref_pa : ndarray or None
        An independent reference static pressure, Pa (trailing cone, tower fly-by, ground
        barometer plus GPS height), when the flight has one.
    source : str
        Where the data came from (file name), used in error messages.
    meta : dict
        Free-form metadata (the CSV's `# key: value` comment lines).
    n_dropped : int
        Rows the reader dropped (each with a warning), for the report.
    warnings : tuple of str
        Every warning the reader gave about this data (also issued with `warnings.warn`), so
        the result record can carry them.
    tat_k, rh_pct : ndarray or None
        Total air temperature (K) and relative humidity (%), when the data has them
        (`pitotcal.core.moist_air.with_static_air` turns them into `oat_k` and `rho_kgm3`).
    reading : dict or None
        How `pitotcal.io.read_flight` read the file and made its air data, once: start_s,
        end_s, oat_k, temp_recovery, rh_pct, oat_source. None for a flight made in memory.
    segment : ndarray of int or None
        Which calibration window each sample belongs to (0, 1, ...), when the flight is several
        disjoint windows of one log: they share the calibration and each keeps its own wind.
        None: one window.
    """

    time_s: np.ndarray
    qci_pa: np.ndarray
    gps_vn_mps: np.ndarray
    gps_ve_mps: np.ndarray
    rho_kgm3: np.ndarray
    gps_vd_mps: np.ndarray | None = None
    alt_m: np.ndarray | None = None
    ps_pa: np.ndarray | None = None
    oat_k: np.ndarray | None = None
    ps_ref_pa: np.ndarray | None = None
    source: str = "<memory>"
    meta: dict = field(default_factory=dict)
    n_dropped: int = 0
    warnings: tuple = ()
    # temperature and humidity: optional channels
    tat_k: np.ndarray | None = None
    rh_pct: np.ndarray | None = None
    reading: dict | None = None
    segment: np.ndarray | None = None

    @property
    def n(self):
        return int(self.time_s.size)

    def select(self, mask):
        """A new Flight with only the samples where the boolean `mask` is true."""
        pick = {name: (getattr(self, name)[mask] if getattr(self, name) is not None else None)
                for name in _ARRAYS}
        return replace(self, **pick)

    def window(self, start_s=None, end_s=None):
        """The samples with start_s <= time_s <= end_s (either bound may be None)."""
        lo = -np.inf if start_s is None else start_s
        hi = np.inf if end_s is None else end_s
        return self.select((self.time_s >= lo) & (self.time_s <= hi))


_ARRAYS = ("time_s", "qci_pa", "gps_vn_mps", "gps_ve_mps", "rho_kgm3", "gps_vd_mps", "alt_m", "ps_pa",
           "oat_k", "ps_ref_pa", "tat_k", "rh_pct", "segment")


def track_spread_deg(vn_mps, ve_mps):
    """Angular spread of the ground track, degrees: 360 minus the largest empty arc of courses."""
    moving = np.hypot(vn_mps, ve_mps) > 1.0
    if moving.sum() < 2:
        return 0.0
    course = np.sort(np.degrees(np.arctan2(ve_mps[moving], vn_mps[moving])) % 360.0)
    gaps = np.diff(np.concatenate([course, [course[0] + 360.0]]))
    return float(360.0 - gaps.max())
