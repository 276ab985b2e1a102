"""What `identify` will report for a planned flight, by running its own covariance on residuals
drawn from the design's noise model (the `design` study's check of the prediction).

The design (`maneuvers.plan.design`) predicts the reported 2σ of ΔV analytically: the sandwich under
`core.information.gust_covariance`, widened for the noise model's degrees of freedom. `identify`
instead fits its multi-time-scale noise model (`estimation.uncertainty.residual_noise`) to the residuals of
one flight, and that fit varies from flight to flight: it may add slow terms (tens of seconds)
that the fitted parameters' signatures hide from the residuals. Here the residuals of many
draws of the gust, GPS and transducer noise on the planned path (linearised least squares on
a 0.2-s grid, the estimator's own block scale) go through `estimation.uncertainty.covariance.
colored_covariance`; the median of the reported worst-row 2σ is what a flown set of seeds
should show, without the simulator's other effects (autopilot, speed loop).
"""

import numpy as np

__all__ = ["emulated_reported_kt"]


def emulated_reported_kt(plan, turbulence_mps, vi_kt, *, draws=100, seed=0, dt_s=0.2,
                         model="inverse"):
    """(median, mean) over `draws` of the worst 2σ of ΔV at `vi_kt` that `identify`'s colored
    covariance reports for residuals drawn on `plan`'s path, kt.

    Parameters
    ----------
    plan : pitotcal.core.plan.Plan
    turbulence_mps : float
        RMS Dryden gust along the path (the design's noise model, `maneuvers.plan.design.
        default_noise`).
    vi_kt : array_like
        Indicated airspeeds of the ΔV rows.
    draws, seed : int
        Number of residual draws, seed of their generator.
    dt_s : float
        Grid spacing of the draws, s.
    """
    from pitotcal.estimation.uncertainty.covariance import colored_covariance
    from pitotcal.maneuvers.plan.design import default_noise
    from scipy.signal import lfilter

    from pitotcal.core.information import delta_v_band_kt, qci_sensitivities
    from pitotcal.core.models import get_model
    from pitotcal.core.scenario import true_k
    from pitotcal.core.units import isa_density_kgm3, wind_vector_mps

    pe, k = get_model(model), true_k(model)
    s = plan.settings
    rho = float(isa_density_kgm3(float(np.mean(plan.alt_m))))
    noise = default_noise(turbulence_mps, float(np.mean(plan.alt_m)), plan.tas_mps)
    t = np.arange(plan.time_s[0], plan.time_s[-1], dt_s)
    heading = np.interp(t, plan.time_s, np.unwrap(np.radians(plan.heading_deg)))
    jac = qci_sensitivities(np.interp(t, plan.time_s, plan.tas_mps), heading, rho, pe, k,
                            wind_vector_mps(s.get("wind_speed_mps", 0.0),
                                            s.get("wind_from_deg", 0.0)))
    w = np.sqrt(np.sum(jac[:, -2:] ** 2, axis=1))
    white = np.sqrt(noise.qc_noise_pa ** 2 / max(dt_s * noise.rate_hz, 1.0)
                    + (w * noise.gps_noise_mps) ** 2 / max(dt_s * noise.gps_rate_hz, 1.0))
    a = np.exp(-dt_s / noise.tau_s)
    rng = np.random.default_rng(seed)
    shocks = rng.standard_normal((draws, t.size))
    shocks[:, 0] /= np.sqrt(1.0 - a * a)            # the AR(1) gust starts stationary
    gust = turbulence_mps * np.sqrt(1.0 - a * a) * lfilter([1.0], [1.0, -a], shocks, axis=1)
    q, _ = np.linalg.qr(jac)
    worst = []
    for g in gust:
        e = w * g + white * rng.standard_normal(t.size)
        r = e - q @ (q.T @ e)                       # what the fit leaves
        cov = colored_covariance(jac, r, velocity=jac[:, -2:]).covariance
        worst.append(float(delta_v_band_kt(pe, k, cov[:2, :2], vi_kt).max()))
    return float(np.median(worst)), float(np.mean(worst))
