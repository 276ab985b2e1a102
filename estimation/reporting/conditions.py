"""The test conditions the report states in words: how turbulent the air was.

The turbulence indication rests on the output residual as equivalent airspeed: a gust u along
the flight path moves q_ci by rho V u, so the residual RMS over rho V is the along-path gust
RMS (plus the GPS velocity and transducer noise: an upper bound). It takes the result JSON
alone (`noise_std_pa` and the correction table's speeds), so a report without the flight says
it too.
"""

import math

__all__ = ["TURBULENCE_WORDS", "turbulence_rms_mps", "turbulence_text"]


# Turbulence words by the RMS gust along the flight path, m/s. MIL-HDBK-1797 (MIL-F-8785C)
# low-altitude Dryden: sigma_w = 0.1 W20 with W20 = 15 / 30 / 45 kt for light / moderate /
# severe, i.e. sigma ~ 0.8 / 1.5 / 2.3 m/s (sigma_u >= sigma_w below 1000 ft). A word applies
# from about the geometric mean of its level and the one below; below a quarter of light's,
# the residual is GPS and transducer noise, not air.
TURBULENCE_WORDS = ((0.2, "calm"), (1.1, "light"), (2.0, "moderate"), (math.inf, "severe"))


def turbulence_rms_mps(result):
    """The output residual RMS as equivalent airspeed, m/s: noise_std_pa / sqrt(mean((rho0
    V_i)^2)) over the correction table's speeds (dq_c/dV = rho V). A gust u along the path
    moves q_ci by rho V u, so this is the along-path gust RMS, plus the GPS velocity and
    transducer noise (an upper bound); None when the result lacks noise_std_pa or speeds."""
    from pitotcal.core.units import RHO0_KGM3, kt_to_mps

    noise = result.get("noise_std_pa")
    vi = [r["vi_kt"] for r in result.get("airspeed_correction") or []
          if r.get("vi_kt") is not None]
    if noise is None or not vi or not math.isfinite(noise):
        return None
    rho_v = RHO0_KGM3 * kt_to_mps(vi)
    return float(noise / math.sqrt(float((rho_v ** 2).mean())))


def turbulence_text(result):
    """The turbulence word of `TURBULENCE_WORDS` and the airspeed RMS it rests on."""
    from pitotcal.core.units import mps_to_kt

    sigma = turbulence_rms_mps(result)
    if sigma is None:
        return "—"
    word = next(w for top, w in TURBULENCE_WORDS if sigma < top)
    return (f"{word}: residual {sigma:.2f} m/s ({mps_to_kt(sigma):.1f} kt) RMS of equivalent "
            "airspeed, gusts along the path plus GPS noise (light / moderate / severe ≈ "
            "0.8 / 1.5 / 2.3 m/s, MIL-HDBK-1797)")
