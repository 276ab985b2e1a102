"""`IdentificationResult`: what `identify` returns, with the airspeed-correction table."""

from dataclasses import dataclass, field

import numpy as np

from pitotcal.core.models import delta_v_kt, get_model
from pitotcal.core.propagation import band as _band
from pitotcal.core.propagation import gradient as _gradient

from .unknowns import COEFS

__all__ = ["IdentificationResult"]


@dataclass(frozen=True)
class IdentificationResult:
    """Outcome of an output-error identification.

    Attributes
    ----------
    model : str
        Pressure-error structure (`pitotcal.core.models.MODELS`).
    param_names : tuple of str
        Reported parameters: the model's coefficients, then `wind_speed_mps`, `wind_from_deg`.
    params : ndarray, shape (p,)
    covariance : ndarray, shape (p, p)
        Covariance corrected for colored residuals; `std` and every 2-sigma band use it.
    covariance_plain : ndarray, shape (p, p)
        Plain Hessian (Cramer-Rao) covariance s^2 (J^T J)^-1, for comparison.
    internal_params, internal_covariance, internal_covariance_plain : ndarray
        The same in the solver's parameters: coefficients, `wind_n_mps`, `wind_e_mps`.
    success : bool
        The solver converged (scipy `OptimizeResult` naming).
    message : str
        The solver's status.
    iterations : int
    n_samples : int
    noise_std_pa : float
        RMS of the residuals, Pa.
    gps_noise_std_mps : float
        GPS velocity noise sigma_v used for the errors-in-variables correction, m/s.
    time_s, qci_pa, rho_kgm3, residuals_pa : ndarray, shape (N,)
        Data used and output residual q_ci - predicted q_ci, Pa.
    warnings : tuple of str
    candidates : tuple of dict
        With `--model auto`: every structure tried and its criterion.
    criterion : str or None
        The information criterion used to choose among candidates.
    timing_s : dict
        Seconds spent in `build`, `solve`, `covariance`.
    air_data : {"incompressible", "compressible"}
        How q_c was predicted from V_t (`estimation.identify`, `air`), and so which airspeed
        law the correction table uses: sqrt(2 q / rho0), or the standard calibrated airspeed
        (V_i is then V_ic and ΔV the position-error correction ΔV_pc).
    ps_pa : ndarray, shape (N,), or None
        The static source's pressure used (compressible only): sets the flight's pressure
        altitude for the altimeter correction.
    ps_ref_pa : ndarray, shape (N,), or None
        The flight's independent reference static pressure, when it had one (compressible):
        the prediction used it, and it separates static from total pressure error
        (`estimation.identification.static_source`).
    consistency : dict
        The step-change consistency test's numbers (`estimation.robustness.consistency.step_test`
        details; empty when it did not run): docs/interfaces.md §20.
    static_fit : (ndarray, ndarray) or None
        The measured static-error fit (k_static, its covariance) of a result with a reference
        static pressure (`estimation.identification.static_source.static_error_fit`), fitted
        once by `identify`; None otherwise.
    monitor_noise : dict or None
        The residuals' noise model on the monitor's blocks (`estimation.monitor.model.noise_model`;
        the record's ``"noise_model"``); None for a record too short for it.
    gps_error : dict or None
        The stated GPS velocity error: {stated, sigma_mps, tau_s}.
    reading : dict or None
        How `pitotcal.io.read_flight` read the flight: {start_s, end_s, oat_k, temp_recovery,
        rh_pct, oat_source}; None for a flight made in memory.
    budget : Budget or None
        The GUM uncertainty budget (`identify(..., budget=...)`).
    source : str
        The flight's source (file or stream).
    n_dropped : int
        Rows (or log samples) the reader dropped.
    wind_model : dict or None
        How the wind was modelled (`estimation.identification.wind_drift`): {kind ("constant",
        "constant per window" or "drifting"), knot_s, test (the Wald test of no drift, or
        None), chosen_by}.
    wind_track : dict or None
        The wind along the record: {time_s, speed_mps, from_deg, speed_2sigma_mps,
        from_2sigma_deg[, segment]} (two points for a constant wind).
    drift : (DriftBasis, ndarray) or None
        The fitted drift of a drifting wind or of one wind per window
        (`wind_drift.without_drift` takes it out of a flight's GPS velocity); None for a
        constant wind.
    """

    model: str
    param_names: tuple
    params: np.ndarray
    covariance: np.ndarray
    covariance_plain: np.ndarray
    internal_params: np.ndarray
    internal_covariance: np.ndarray
    internal_covariance_plain: np.ndarray
    success: bool
    message: str
    iterations: int
    n_samples: int
    noise_std_pa: float
    gps_noise_std_mps: float
    time_s: np.ndarray
    qci_pa: np.ndarray
    rho_kgm3: np.ndarray
    residuals_pa: np.ndarray
    warnings: tuple = ()
    candidates: tuple = ()
    criterion: str | None = None
    timing_s: dict = field(default_factory=dict)
    air_data: str = "incompressible"
    ps_pa: np.ndarray | None = None
    ps_ref_pa: np.ndarray | None = None
    consistency: dict = field(default_factory=dict)
    static_fit: tuple | None = None
    monitor_noise: dict | None = None
    gps_error: dict | None = None
    reading: dict | None = None
    budget: object = None
    source: str = "<memory>"
    n_dropped: int = 0
    wind_model: dict | None = None
    wind_track: dict | None = None
    drift: tuple | None = None

    # --- derived quantities -------------------------------------------------------------
    @property
    def converged(self):
        return self.success

    @property
    def std(self):
        return np.sqrt(np.diag(self.covariance))

    @property
    def std_plain(self):
        return np.sqrt(np.diag(self.covariance_plain))

    @property
    def correlation(self):
        s = self.std
        with np.errstate(invalid="ignore", divide="ignore"):
            return self.covariance / np.outer(s, s)

    @property
    def coefficients(self):
        """The model's own coefficients (k1, k2, ...)."""
        return self.internal_params[COEFS]

    def value(self, name):
        return float(self.params[self.param_names.index(name)])

    def stddev(self, name, plain=False):
        cov = self.covariance_plain if plain else self.covariance
        i = self.param_names.index(name)
        return float(np.sqrt(cov[i, i]))

    def pressure_error(self, qci_pa, plain=False):
        """Δp/q_c at `qci_pa` and its 2-sigma half-width (delta method)."""
        model = get_model(self.model)
        k = self.coefficients
        qci = np.asarray(qci_pa, dtype=float)
        ratio = model(k, qci)
        grad = _gradient(lambda kk: model(kk, qci), k)
        return ratio, 2.0 * _band(grad, self._coef_cov(plain))

    def delta_v_kt(self, vi_kt, plain=False):
        """Airspeed correction ΔV = V_c - V_i (kt) at indicated `vi_kt` and its 2-sigma half-width.

        q_c = q_ci / (1 - f(q_ci)); V_i and V_c are the airspeeds of q_ci and q_c by the law of
        `air_data` (`pitotcal.core.models.delta_v_kt`): sqrt(2 q / rho0), or the standard
        calibrated airspeed (ΔV = ΔV_pc, V_i = V_ic).
        """
        model = get_model(self.model)
        k = self.coefficients
        grad = _gradient(lambda kk: delta_v_kt(model, kk, vi_kt, self.air_data), k)
        return (delta_v_kt(model, k, vi_kt, self.air_data),
                2.0 * _band(grad, self._coef_cov(plain)))

    # --- presentation (estimation.identification.view, .record) --------------------------------------------
    def summary(self):
        """Human summary in knots and degrees (what `pitotcal identify` prints)."""
        from .view import summary
        return summary(self)

    def to_dict(self):
        """The record `pitotcal identify --json` writes (docs/interfaces.md §3): computes
        nothing `identify` has not (`estimation.identification.record.to_dict`)."""
        from .record import to_dict
        return to_dict(self)

    def correction_table(self, step_kt=None):
        """Airspeed-correction rows {vi_kt, dv_kt, dv_2sigma_kt} over the flown V_i range."""
        from .view import correction_table
        return correction_table(self, step_kt=step_kt)

    def plot(self, path=None):
        """The calibration figure (paper Figs. 7-8 style); saved to `path` when given."""
        from .view import plot
        return plot(self, path)

    def _coef_cov(self, plain):
        cov = self.internal_covariance_plain if plain else self.internal_covariance
        return cov[COEFS, COEFS]
