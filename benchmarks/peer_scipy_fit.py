"""The plain scipy baseline of `bench_peers_speed.py`: the same fit as `pitotcal identify`'s
default, written as a user would with numpy and scipy alone.

Run: ``python benchmarks/peer_scipy_fit.py FLIGHT.csv [SPEED_KT ...]`` (a pitotcal flight CSV).
As identify: with static pressure and temperature (ps_pa, oat_k) the compressible relation
q_c = p_s ((1 + 0.2 M^2)^3.5 - 1), M = |V_gps - W| / sqrt(1.4 R T), else q_c = rho V^2 / 2.
Model: the inverse pressure error dp/q_c = k1 + k2/q_ci, so q_ci = (1 - k1 - k2/q_ci) q_c, with a
constant horizontal wind W. `least_squares` (Levenberg-Marquardt,
analytic Jacobian) on the pressure residual; the covariance is the HAC (Newey-West, Bartlett
weights, lag floor(4 (n/100)^(2/9))) sandwich, because the residuals are autocorrelated (held
GPS, turbulence). Prints one JSON line: k1, k2, the wind and dV = V_c - V_i at 70, 84, 98 kt.
"""

import json
import sys

import numpy as np
from scipy.optimize import least_squares

RHO0_KGM3 = 1.225
KT_MPS = 1852.0 / 3600.0
SPEEDS_KT = (70.0, 84.0, 98.0)


def read(path):
    names, skip = header(path)
    compressible = "ps_pa" in names and "oat_k" in names
    last = ("ps_pa", "oat_k") if compressible else ("rho_kgm3",)
    cols = [names.index(c) for c in ("qc_pa", "gps_vn_mps", "gps_ve_mps") + last]
    data = np.loadtxt(path, delimiter=",", skiprows=skip, usecols=cols, comments="#")
    return data.T, compressible


def header(path):
    """(column names, lines up to and with them): the first line that is not a # comment."""
    with open(path) as f:
        for i, line in enumerate(f):
            if not line.startswith("#"):
                return line.strip().split(","), i + 1
    return [], 0


def impact_pressure(v2, air):
    """(q_c, dq_c/d(V^2)) for squared true airspeed v2 and air = (rho,) or (p_s, T)."""
    if len(air) == 1:
        return 0.5 * air[0] * v2, 0.5 * air[0]
    ps, temp = air
    m2 = v2 / (1.4 * 287.05287 * temp)
    base = 1 + 0.2 * m2
    return ps * (base ** 3.5 - 1), ps * 0.7 * base ** 2.5 / (1.4 * 287.05287 * temp)


def fit(q, vn, ve, air):
    scale = np.array([0.01, 10.0, 1.0, 1.0])        # k1, k2 Pa, wind N, E m/s: unit steps

    def res(x):
        k1, k2, wn, we = x * scale
        return q - (1 - k1 - k2 / q) * impact_pressure((vn - wn) ** 2 + (ve - we) ** 2, air)[0]

    def jac(x):
        k1, k2, wn, we = x * scale
        dn, de = vn - wn, ve - we
        qc, dqc = impact_pressure(dn * dn + de * de, air)
        a = 2 * dqc * (1 - k1 - k2 / q)
        return np.column_stack([qc * scale[0], qc / q * scale[1], a * dn, a * de])

    sol = least_squares(res, np.zeros(4), jac=jac, method="lm", xtol=1e-12, ftol=1e-12)
    return sol.x * scale, sol.fun, sol.jac / scale


def hac_covariance(r, jac):
    """Newey-West sandwich (J'J)^-1 S (J'J)^-1 of the least-squares estimate."""
    n = r.size
    lags = int(4 * (n / 100.0) ** (2.0 / 9.0))
    g = jac * r[:, None]
    meat = g.T @ g
    for lag in range(1, lags + 1):
        gamma = g[lag:].T @ g[:-lag]
        meat += (1 - lag / (lags + 1)) * (gamma + gamma.T)
    bread = np.linalg.inv(jac.T @ jac)
    return bread @ meat @ bread, lags


def cas_kt(qc, compressible):
    """Calibrated airspeed (kt) of impact pressure qc: the standard relation, or sqrt(2 q/rho0)."""
    if not compressible:
        return np.sqrt(2 * qc / RHO0_KGM3) / KT_MPS
    return 340.294 * np.sqrt(5 * ((qc / 101325.0 + 1) ** (2 / 7) - 1)) / KT_MPS


def qc_of_cas(v_kt, compressible):
    if not compressible:
        return 0.5 * RHO0_KGM3 * (v_kt * KT_MPS) ** 2
    return 101325.0 * ((1 + 0.2 * (v_kt * KT_MPS / 340.294) ** 2) ** 3.5 - 1)


def main(path, speeds_kt):
    (q, vn, ve, *air), compressible = read(path)
    theta, r, jac = fit(q, vn, ve, air)
    cov, lags = hac_covariance(r, jac)
    k1, k2, wn, we = theta
    dv, dv2s = [], []
    for v in speeds_kt:
        qi = qc_of_cas(v, compressible)

        def dv_of(k):
            return float(cas_kt(qi / (1 - k[0] - k[1] / qi), compressible) - v)
        dv.append(dv_of(theta[:2]))
        steps = np.sqrt(np.diag(cov[:2, :2])) * 1e-3      # d dV / d(k1, k2), central differences
        grad = np.array([(dv_of(theta[:2] + e) - dv_of(theta[:2] - e)) / (2 * e[i])
                         for i, e in enumerate(np.diag(steps))])
        dv2s.append(2 * float(np.sqrt(grad @ cov[:2, :2] @ grad)))
    print(json.dumps({"k1": k1, "k2": k2, "k1_std": float(np.sqrt(cov[0, 0])),
                      "k2_std": float(np.sqrt(cov[1, 1])),
                      "wind_speed_mps": float(np.hypot(wn, we)),
                      "wind_from_deg": float(np.degrees(np.arctan2(-we, -wn)) % 360),
                      "speeds_kt": list(speeds_kt), "compressible": compressible, "dv_kt": dv, "dv_2sigma_kt": dv2s,
                      "n": int(q.size), "hac_lags": lags}))


if __name__ == "__main__":
    main(sys.argv[1], [float(v) for v in sys.argv[2:]] or SPEEDS_KT)
