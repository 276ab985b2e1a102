"""The fit's estimate on slightly perturbed data from its sensitivities, without solving again.

The reported estimate θ̂ is the root of the refined estimating equations g(θ; data) = 0
(`iv.estimating_equations`: the instrumental-variable rows of the coefficients and the
corrected-score rows of the wind). On data moved by a small Δp the root moves, by the
implicit-function theorem, by

    Δθ = −J⁻¹ [g(θ̂; data + Δp) − g(θ̂; data)],      J = ∂g/∂θ at θ̂,

which is what a re-solve (IPOPT, then the same refinement) finds to first order in Δθ. The
difference of g is taken on the perturbed data themselves, so it is exact in Δp (a
perturbation that is not linear in its step, the GPS latency, keeps its second-order part),
and the same estimator is linearised: the fitted samples (the gates and the outlier trimming
of the fit, not done again), the GPS noise it used, its air data and its instruments.

J is formed once per result (p + 1 evaluations of g). The first-order step is then repeated
with the same J (chord steps, each one O(N) evaluation of g) until it is below `REL_TOL` of
the first (or `STEP_TOL`), so the estimate is the perturbed equations' root, the re-solve's,
to a fraction of a percent of its change, and not only its first-order part: where the
coefficients are strongly correlated (k1 and k2 at 0.99+) the change of J with the data
turns a 0.2 % transducer scale into a 6 % second step in k1/k2 (measured on the tests'
flight), then 0.02 % in the third; a 1 % scale takes 7 steps, each below 0.6 of the one
before. Steps that do not shrink by `CONTRACTION` each time, or more than `MAX_STEPS`,
refuse (`NotLinear`) and the caller re-solves. The steps converge to the root whatever small
error J has, so J is a forward difference (its error changes how fast, not where to).
"""

import dataclasses

import numpy as np

from pitotcal.core.gps_velocity import interpolate_held
from pitotcal.core.measurement import flight_channels
from pitotcal.core.models import get_model

from .iv import (
    IV_NOT_CONVERGED,
    IV_WINDOW_S,
    equation_values,
    smooth_in_time,
    window_bounds,
)
from .unknowns import theta_scales, to_reported

__all__ = ["CONTRACTION", "MAX_STEPS", "REL_TOL", "STEP_TOL", "Linearised", "NotLinear"]

# A chord step below this in the scaled unknowns ends the steps: IPOPT's tol and the
# refinement's own, far below any sigma.
STEP_TOL = 1e-6
# A chord step below this fraction of the first ends the steps too: what is left of the change
# is then about the contraction rate times this (measured rates 0.003-0.6), below 1 % of a
# budget term whose tests ask 5 %.
REL_TOL = 1e-2
# Each chord step at most this fraction of the one before, else the linearisation is no good
CONTRACTION = 0.9
MAX_STEPS = 12
# Step of the forward differences of g in the scaled unknowns (their coefficients O(1)).
_FD_STEP = 1e-4


class NotLinear(Exception):
    """The linearisation does not give this estimate: the caller re-solves (message: why)."""


class Linearised:
    """`result`'s estimator linearised at its estimate on the samples of `flight` it fitted.

    Parameters
    ----------
    flight : pitotcal.core.flight.Flight
        The flight `result` was fitted on, before its gates and trimming (its fitted samples
        are found by their times).
    result : IdentificationResult

    Attributes
    ----------
    fitted : pitotcal.core.flight.Flight
        The samples `result` was fitted on; `solve` takes them perturbed.

    Raises
    ------
    NotLinear
        When the estimate is not the root of the refined equations (the refinement did not
        converge, the solver did not) or the fitted samples are not found in `flight`.
    """

    def __init__(self, flight, result):
        if not result.success or any(IV_NOT_CONVERGED in w for w in result.warnings):
            raise NotLinear("the estimate is not the root of the refined estimating equations")
        keep = np.isin(flight.time_s, result.time_s)
        if int(keep.sum()) != result.n_samples or not np.array_equal(flight.time_s[keep],
                                                                     result.time_s):
            raise NotLinear("the fitted samples are not found by their times")
        self.result = result
        self.model = get_model(result.model)
        self.air_data = ("incompressible" if result.air_data == "incompressible" else
                         "reference" if result.ps_ref_pa is not None else "compressible")
        self.theta = np.asarray(result.internal_params, dtype=float)
        self.scales = theta_scales(self.model)
        # the fitted samples, which `solve` takes perturbed; what depends on their times and
        # GPS alone is kept for perturbations that keep those
        self.fitted = kept = flight if keep.all() else flight.select(keep)
        self.bounds = window_bounds(kept.time_s, IV_WINDOW_S)
        self.held = interpolate_held(kept.time_s, *self._gps(kept))
        ch = flight_channels(kept, result.gps_noise_std_mps, self.air_data, held=self.held)
        self.q_smooth = smooth_in_time(ch.qci, kept.time_s, IV_WINDOW_S, self.bounds)
        self.g0 = self._g(self.theta, ch, self.q_smooth)
        # p x p (p <= 5): solved at each step, no factorisation to keep (and no scipy.linalg
        # import, 0.4 s, in every command that imports the budget)
        self.jacobian = self._jacobian(ch, self.q_smooth)

    @staticmethod
    def _gps(flight):
        return tuple(c for c in (flight.gps_vn_mps, flight.gps_ve_mps, flight.gps_vd_mps)
                     if c is not None)

    def _channels(self, kept):
        """(channels, smoothed q_ci) of `fitted` perturbed (`kept`); the GPS interpolation
        and the smoothing reused where the perturbation kept their inputs (the same arrays)."""
        same_gps = all(a is b for a, b in zip(self._gps(kept), self._gps(self.fitted)))
        ch = flight_channels(kept, self.result.gps_noise_std_mps, self.air_data,
                             held=self.held if same_gps else None)
        if kept.qci_pa is self.fitted.qci_pa:
            return ch, self.q_smooth
        return ch, smooth_in_time(ch.qci, kept.time_s, IV_WINDOW_S, self.bounds)

    def _g(self, theta, ch, q_smooth):
        return equation_values(self.model, theta, ch, q_smooth)

    def _jacobian(self, ch, q_smooth):
        """J = ∂g/∂θ at θ̂ by forward differences in the scaled unknowns."""
        cols = []
        for i, scale in enumerate(self.scales):
            h = np.zeros_like(self.theta)
            h[i] = _FD_STEP * scale
            cols.append((self._g(self.theta + h, ch, q_smooth) - self.g0) / h[i])
        return np.column_stack(cols)

    def _step(self, theta, ch, q_smooth):
        """−J⁻¹ [g(θ; perturbed) − g(θ̂; unperturbed)]; a singular J is `NotLinear`."""
        try:
            return -np.linalg.solve(self.jacobian, self._g(theta, ch, q_smooth) - self.g0)
        except np.linalg.LinAlgError:
            raise NotLinear("its Jacobian is singular") from None

    def solve(self, perturbed):
        """`result` with the estimate θ̂ + Δθ of `perturbed`: `fitted` perturbed.

        Returns
        -------
        IdentificationResult
            `params` and `internal_params` moved; its data (q_ci, ρ, p_s) the perturbed
            samples', as a re-solve's; no static-error fit of its own
            (`static_source.fitted_static_error` fits it again, as for a re-solve).

        Raises
        ------
        NotLinear
            When the chord steps do not converge (`CONTRACTION`, `MAX_STEPS`).
        """
        ch, q_smooth = self._channels(perturbed)
        theta, last, first = self.theta, np.inf, None
        for _ in range(MAX_STEPS):
            step = self._step(theta, ch, q_smooth)
            theta = theta + step
            size = float(np.max(np.abs(step / self.scales)))
            if not np.isfinite(size) or size > CONTRACTION * last:
                raise NotLinear("its linearised steps do not converge")
            first = size if first is None else first
            if size < STEP_TOL or size < REL_TOL * first:
                break
            last = size
        else:
            raise NotLinear(f"its linearised steps do not converge in {MAX_STEPS}")
        params, _ = to_reported(theta, self.result.internal_covariance)
        kept = perturbed
        compressible = self.result.air_data != "incompressible"
        return dataclasses.replace(
            self.result, params=params, internal_params=theta, qci_pa=kept.qci_pa,
            rho_kgm3=kept.rho_kgm3, ps_pa=kept.ps_pa if compressible else None,
            ps_ref_pa=kept.ps_ref_pa if self.air_data == "reference" else None,
            static_fit=None, budget=None)
