"""The uncertainty budget of the airspeed correction (GUM): statistical part plus Type B inputs.

    u_c(V_i)² = (σ_stat)² + Σ_j u_j(V_i)²,      U = k u_c,  k = 2

σ_stat is the estimate's own standard deviation (the colored-residual covariance:
`dv_2sigma_kt` / 2). Each Type B input x_j (a quantity the fit takes as exact) has a standard
uncertainty u(x_j) with a documented default the user can override (`BudgetInputs`). The
flight is perturbed to x_j ± u(x_j) and the estimate on each found with the same model and GPS
noise, and at each table speed

    u_j(V_i) = sqrt((d₊² + d₋²) / 2),   d± = ΔV(V_i; x_j ± u) − ΔV(V_i; x_j)

The estimates on the perturbed flights come from the fit's sensitivities (`linearised`: the
Jacobian J of the fit's estimating equations g formed once, then a few evaluations of g per
perturbed flight, Δθ = −J⁻¹ Δg repeated to the root; method "sensitivity", the default) or
from re-solving `estimate` on each (method "resolve"). A term whose linearised steps do not converge
(`linearised.CONTRACTION`) is re-solved, with a note; the tests check that both agree.

For an effect linear in x_j this is |∂ΔV/∂x_j| u, the GUM's first-order term; when the effect
is not linear (the GPS latency is partly quadratic: a misalignment either way degrades the
fit alike) it keeps the second-order part a central difference would cancel. The tests check
each term against re-solves at half the step and against the bias the simulator injects.
The inputs and what is perturbed; the defaults come from the sensor class and, for the OAT, the
temperature's source (`sensor_inputs`, which also lists where each value came from):

- oat: static air temperature; the density ρ → ρ T/(T ± u) and the static temperature itself.
- humidity: relative humidity, u = 5 %RH with a humidity channel or --rh-percent, else 58 %RH
  (= 100/√3: dry air assumed while the truth is anywhere in 0-100 %, so the error is one-sided
  and its RMS is the effect at 100/√3, not the 50/√3 of an estimate centred at 50 %); ρ
  through the virtual temperature.
- gps_velocity_bias: a constant GPS velocity error per axis (u-blox M8/M9 speed accuracy,
  0.05 m/s). A horizontal bias b is the wind's: V_g + b − W = V_g − (W − b), so the fitted wind
  absorbs it exactly and ΔV does not move (the tests re-solve to show it); only the vertical
  channel is re-solved.
- gps_latency: the GPS velocity's age relative to the pressure (a receiver's latency known to
  within a navigation cycle); the GPS channels shifted in time.
- probe_lever_arm: a probe at y = arm on the wing sees V_t − r·y in a turn at yaw rate r
  (ω × r), r = ψ̇ cos φ from the air-relative heading rate, tan φ = V ψ̇/g. A known arm is
  corrected in the data (`lever_arm_corrected`, `identify(..., probe_arm_m=)`); this term is
  the arm's own uncertainty: q_ci → q_ci (1 ∓ r·u / V_t)².
- qc_scale, qc_offset: the differential transducer's gain and zero: ΔV_pc is the position
  error only if the transducer's own error is known to this.
- static_pressure: the static transducer: p_s ± u and the density made of it (ρ ∝ p_s); it
  moves the compressibility and the density the TAS comes from.

A compressible result's static-source products, the altimeter correction ΔH_pc (ft) and the
Mach correction ΔM_pc, get the same budget from the same re-solves: each perturbed calibration
is carried to ΔH and ΔM at the table's speeds (`static_source.static_source_products`) and
differenced as ΔV is, and the statistical part is their own 2σ / 2 (`Budget.products`).
"""

import dataclasses
import warnings

import numpy as np

from pitotcal.core import checks
from pitotcal.core.errors import PitotcalError
from pitotcal.core.models import delta_v_kt_where_defined, get_model
from pitotcal.core.moist_air import moist_density_kgm3
from pitotcal.core.units import (
    G0_MPS2,
    ISA_T0_K,
    R_AIR_JKGK,
    isa_temperature_k,
    wind_vector_mps,
)

from .linearised import Linearised, NotLinear
from .sensor_inputs import RH_U_GIVEN_PCT, RH_U_UNKNOWN_PCT, BudgetInputs, resolve

__all__ = ["COVERAGE_K", "METHODS", "RH_U_GIVEN_PCT", "RH_U_UNKNOWN_PCT", "SOURCES", "Budget",
           "BudgetInputs", "uncertainty_budget"]

COVERAGE_K = 2.0
# How the perturbed estimates are found: the fit's sensitivities, or re-solves
METHODS = ("sensitivity", "resolve")
# (source name in the JSON, BudgetInputs field of its standard uncertainty, unit)
SOURCES = (
    ("oat", "u_oat_k", "K"),
    ("humidity", "u_rh_pct", "%RH"),
    ("gps_velocity_bias", "u_gps_velocity_mps", "m/s"),
    ("gps_latency", "u_gps_latency_s", "s"),
    ("probe_lever_arm", "u_probe_arm_m", "m"),
    ("qc_scale", "u_qc_scale", "1"),
    ("qc_offset", "u_qc_offset_pa", "Pa"),
    ("static_pressure", "u_ps_pa", "Pa"),
)
@dataclasses.dataclass(frozen=True)
class Budget:
    """The budget over the correction table's speeds.

    Attributes
    ----------
    vi_kt : ndarray (m,)
        Indicated airspeeds of the correction table, kt.
    statistical_kt : ndarray (m,)
        σ_stat = dv_2sigma_kt / 2, kt.
    terms_kt : dict
        Source name -> u_j at each speed, kt (`SOURCES` order).
    inputs : dict
        Source name -> (standard uncertainty of the input, unit).
    warnings : tuple of str
    products : dict
        Static-source product ("dh_ft", "dmach") -> {"statistical": σ at each speed, source
        name -> u_j at each speed}, in the product's unit; empty for an incompressible result.
    input_list : tuple of dict
        Every input with its value and where it came from ({input, value, unit, origin}:
        `sensor_inputs.resolve`): the JSON's ``budget_inputs``.
    """

    vi_kt: np.ndarray
    statistical_kt: np.ndarray
    terms_kt: dict
    inputs: dict
    warnings: tuple = ()
    products: dict = dataclasses.field(default_factory=dict)
    input_list: tuple = ()

    @property
    def combined_kt(self):
        """u_c at each speed, kt."""
        total = self.statistical_kt ** 2 + sum(t ** 2 for t in self.terms_kt.values())
        return np.sqrt(total)

    @property
    def expanded_kt(self):
        """U = k u_c, k = 2, at each speed, kt."""
        return COVERAGE_K * self.combined_kt

    def product_expanded(self, name):
        """U = k u_c of a static-source product (`products`) at each speed."""
        terms = self.products[name]
        return COVERAGE_K * np.sqrt(sum(t ** 2 for t in terms.values()))

    def product_row(self, i):
        """The correction row's static-source budget keys at speed index `i`: dh_U_ft,
        u_dh_by_source_ft, dmach_U, u_dmach_by_source (empty without `products`)."""
        out = {}
        for key, (u_key, by_key) in _PRODUCT_KEYS.items():
            if key in self.products:
                out[u_key] = float(self.product_expanded(key)[i])
                out[by_key] = {n: float(u[i]) for n, u in self.products[key].items()}
        return out

    def to_list(self):
        """The JSON's `uncertainty_budget`: statistical first, each u_dv_kt its max over V_i."""
        rows = [{"source": "statistical", "u_dv_kt": float(np.max(self.statistical_kt))}]
        origin = {r["input"]: r["origin"] for r in self.input_list}
        fields = {name: field for name, field, _ in SOURCES}
        for name, u in self.terms_kt.items():
            u_in, unit = self.inputs[name]
            row = {"source": name, "u_dv_kt": float(np.max(u)), "u_input": u_in, "unit": unit}
            if fields.get(name) in origin:
                row["origin"] = origin[fields[name]]
            rows.append(row)
        return rows


def uncertainty_budget(flight, result, inputs=None, *, method="sensitivity", **identify_kwargs):
    """The GUM budget of `result`'s airspeed correction, from its estimate on perturbed flights.

    Parameters
    ----------
    flight : pitotcal.core.flight.Flight
        The flight `result` was identified from (as passed to `identify`; corrected here for
        the probe lever arm `identify` corrected it for, `result.reading["probe_arm_m"]`).
    result : IdentificationResult
    inputs : BudgetInputs, optional
        Standard uncertainties of the Type B inputs; default `BudgetInputs()`.
    method : {"sensitivity", "resolve"}
        "sensitivity": each perturbed estimate from the fitted problem's sensitivities
        (`linearised.Linearised`), a term re-solved only where the linearisation is not good;
        "resolve": every perturbed estimate re-solved.
    **identify_kwargs
        Passed on to `identify` for every re-solve (e.g. `air=`); the model is `result.model`
        and the GPS noise `result.gps_noise_std_mps`, so only the perturbed input differs.

    Returns
    -------
    Budget
        Over the speeds of `result.correction_table()`.

    Notes
    -----
    Two perturbed estimates per source with a nonzero uncertainty (the GPS bias only with a
    vertical channel). By sensitivities each costs two or three O(N) evaluations of the
    estimating equations (`linearised`); a re-solve is `identification.estimate`, identify's
    estimate without the bounds and consistency checks the budget does not use, at most 16
    (benchmarks/bench_budget.py measures both). A compressible result's ΔH_pc and ΔM_pc get
    their budget from the same perturbed estimates (`Budget.products`).
    """
    checks.choice("method", method, METHODS)
    solved = {}                         # source -> its two perturbed estimates, for ΔH and ΔM
    budget = _resolved_budget(flight, result, inputs, identify_kwargs, solved, method)
    return dataclasses.replace(budget, products=_products_budget(result, budget, solved))


def _resolved_budget(flight, result, inputs, identify_kwargs, solved, method):
    """The airspeed budget of `uncertainty_budget`; each source's perturbed estimates go to
    `solved`."""
    flight = _fitted_samples(flight, result)
    arm_m = (result.reading or {}).get("probe_arm_m")
    if arm_m and not (getattr(flight, "reading", None) or {}).get("probe_arm_m"):
        flight = lever_arm_corrected(flight, result, arm_m)     # re-solve what was fitted
    inputs, input_list = resolve(inputs, flight)
    rows = result.correction_table()
    vi = np.array([r["vi_kt"] for r in rows])
    stat = np.array([r["dv_2sigma_kt"] for r in rows]) / 2.0
    # the re-solves hold a drifting wind's drift at its fit (`flight` has it taken out)
    kwargs = {**identify_kwargs, "gps_noise_std_mps": result.gps_noise_std_mps,
              "model": result.model, "wind": "constant"}
    notes = []
    dv0 = np.asarray(result.delta_v_kt(vi)[0], dtype=float)
    linear = _linearised(flight, result, notes) if method == "sensitivity" else None

    def sensitivity(perturb, name):
        """u at each speed: the RMS of the perturbed estimates' changes at +u and -u; NaN
        (and a note naming the source) where a perturbation or its re-solve is refused or its
        ΔV does not exist."""
        try:
            pair = _perturbed_pair(flight, perturb, name, linear, kwargs, notes)
        except PitotcalError as exc:
            notes.append(f"uncertainty budget: the {name} term is not computed: its "
                         f"perturbed re-solve was refused ({exc})")
            return np.full_like(vi, np.nan)
        dv = [delta_v_kt_where_defined(get_model(res.model), res.coefficients, vi,
                                       res.air_data) - dv0 for res in pair]
        solved[name] = pair
        u = np.sqrt((dv[0] ** 2 + dv[1] ** 2) / 2.0)
        if not np.all(np.isfinite(u)):
            notes.append(f"uncertainty budget: the {name} term is not computed at "
                         f"{int(np.sum(~np.isfinite(u)))} of {vi.size} speeds, where its "
                         "perturbed calibration has no calibrated airspeed")
        return u

    terms = {}
    for name, field, unit in SOURCES:
        u = abs(getattr(inputs, field))
        if u == 0.0:
            terms[name] = np.zeros_like(vi)
        elif name == "gps_velocity_bias":
            # north and east: V_g + b - W = V_g - (W - b), the fit's wind takes b exactly
            # (the tests re-solve to show it); only the vertical channel is left
            terms[name] = (np.zeros_like(vi) if flight.gps_vd_mps is None else
                           sensitivity(lambda f, s, u=u: gps_bias(f, "gps_vd_mps", s * u),
                                       name))
        else:
            perturb = PERTURBATIONS[name]
            terms[name] = sensitivity(lambda f, s, p=perturb, u=u: p(f, result, s * u), name)
    for note in notes:
        warnings.warn(note, stacklevel=2)
    return Budget(vi_kt=vi, statistical_kt=stat, terms_kt=terms,
                  inputs={name: (abs(getattr(inputs, field)), unit)
                          for name, field, unit in SOURCES},
                  warnings=tuple(dict.fromkeys(notes)), input_list=tuple(input_list))


def _linearised(flight, result, notes):
    """`linearised.Linearised` of `result`, or None (and a note) when every term re-solves."""
    try:
        return Linearised(flight, result)
    except NotLinear as exc:
        notes.append(f"uncertainty budget: every term re-solved, not linearised: {exc}")
        return None


def _perturbed_pair(flight, perturb, name, linear, kwargs, notes):
    """The estimates at +u and −u (`perturb(flight, sign)`): linearised when `linear` is given
    and the linearisation is good, else re-solved (a note says which term and why).

    Linearised, the fitted samples are perturbed: a sample the gates dropped stays out (a GPS
    spike shifted in time by the latency term is not let back in at its neighbour, where the
    re-solve's gate finds and drops it again)."""
    from .fit import estimate

    if linear is not None:
        try:
            return [linear.solve(perturb(linear.fitted, sign)) for sign in (1.0, -1.0)]
        except NotLinear as exc:
            notes.append(f"uncertainty budget: the {name} term is re-solved, not linearised: "
                         f"{exc}")
    pair = [estimate(perturb(flight, sign), **kwargs) for sign in (1.0, -1.0)]
    notes.extend(f"uncertainty budget: a perturbed re-solve did not converge ({res.message})"
                 for res in pair if not res.success)
    return pair


# static-source product -> the JSON row's keys of its U and of its terms
_PRODUCT_KEYS = {"dh_ft": ("dh_U_ft", "u_dh_by_source_ft"),
                 "dmach": ("dmach_U", "u_dmach_by_source")}
# static-source product -> the correction table's 2σ column of it
_PRODUCT_BANDS = {"dh_ft": "dh_2sigma_ft", "dmach": "dmach_2sigma"}


def _products_budget(result, budget, solved):
    """`Budget.products`: each product's statistical part (its 2σ / 2) and, per term in the
    budget's order, the RMS change of its two re-solves; a term without them has the ΔV
    term's zeros (no input) or NaN (refused)."""
    from .static_source import static_source_products

    vi = budget.vi_kt
    if result.air_data != "compressible" or result.ps_pa is None:
        return {}
    grid = static_source_products(result, vi)
    out = {}
    for key, band in _PRODUCT_BANDS.items():
        terms = {"statistical": np.asarray(grid[band], dtype=float) / 2.0}
        for name, u_dv in budget.terms_kt.items():
            pair = solved.get(name, [])
            terms[name] = (_rms_change([_static_products(r, vi) for r in pair], key,
                                       np.asarray(grid[key], dtype=float))
                           if len(pair) == 2 else u_dv * 0.0)
        out[key] = terms
    return out


def _static_products(result, vi):
    """{"dh_ft", "dmach"} of a compressible result at the speeds `vi`; {} otherwise (values
    only: a perturbed calibration's bands are not used)."""
    from .static_source import static_source_values

    if result.air_data != "compressible" or result.ps_pa is None:
        return {}
    grid = static_source_values(result, vi)
    return {key: np.asarray(grid[key], dtype=float) for key in ("dh_ft", "dmach")}


def _rms_change(perturbed, key, base):
    """sqrt((d₊² + d₋²) / 2) of a product's change in the two re-solves (NaN where one has
    none: a re-solve refused or a product undefined)."""
    if len(perturbed) < 2 or key not in perturbed[0] or key not in perturbed[1]:
        return np.full_like(base, np.nan)
    d = [p[key] - base for p in perturbed]
    return np.sqrt((d[0] ** 2 + d[1] ** 2) / 2.0)


def _fitted_samples(flight, result):
    """The samples `result` was fitted on: without a collapsed tail it removed
    (`consistency.collapse_onset_s`), so its re-solves are fitted on the same."""
    collapse = (result.consistency or {}).get("collapse")
    if not collapse:
        return flight
    return flight.select(flight.time_s < collapse["removed_from_s"])


# --- perturbed flights (Flight, result, signed step) -> Flight --------------------------------

def static_temperature_of(flight):
    """The flight's static temperature, K: oat_k, else p_s/(R ρ), else ISA at alt_m, else 288.15."""
    if flight.oat_k is not None:
        return np.asarray(flight.oat_k, dtype=float)
    if flight.ps_pa is not None:
        return flight.ps_pa / (R_AIR_JKGK * flight.rho_kgm3)
    if flight.alt_m is not None and np.any(np.isfinite(flight.alt_m)):
        return np.full(flight.n, float(isa_temperature_k(np.nanmean(flight.alt_m))))
    return np.full(flight.n, ISA_T0_K)


def oat_error(flight, result, dt_k):
    """The static temperature dt_k higher: ρ → ρ T/(T + dt), oat_k + dt."""
    t = static_temperature_of(flight)
    out = {"rho_kgm3": flight.rho_kgm3 * t / (t + dt_k)}
    if flight.oat_k is not None:
        out["oat_k"] = flight.oat_k + dt_k
    return dataclasses.replace(flight, **out)


def humidity_error(flight, result, drh_pct):
    """Relative humidity drh_pct higher (lower): ρ and T_v (`oat_k`) through the virtual temperature.

    The density change of +|drh| from the flight's humidity (0 when it has none, capped at
    100 %RH) with the sign of drh, so the two sides of the central difference are symmetric.
    """
    t = static_temperature_of(flight)
    ps = flight.ps_pa if flight.ps_pa is not None else flight.rho_kgm3 * R_AIR_JKGK * t
    rh0 = np.zeros(flight.n) if flight.rh_pct is None else np.asarray(flight.rh_pct, float)
    hi = np.minimum(rh0 + abs(drh_pct), 100.0)
    rel = moist_density_kgm3(ps, t, hi) / moist_density_kgm3(ps, t, rh0) - 1.0
    factor = 1.0 + np.sign(drh_pct) * rel
    out = {"rho_kgm3": flight.rho_kgm3 * factor}
    if flight.oat_k is not None:          # the virtual temperature the compressible fit uses
        out["oat_k"] = flight.oat_k / factor
    return dataclasses.replace(flight, **out)


def gps_bias(flight, channel, bias_mps):
    """A constant bias added to one GPS velocity channel."""
    return dataclasses.replace(flight, **{channel: getattr(flight, channel) + bias_mps})


def gps_latency_error(flight, result, dt_s):
    """The GPS velocity dt_s older relative to the pressure: each channel read at t − dt."""
    t = flight.time_s
    out = {c: np.interp(t - dt_s, t, getattr(flight, c))
           for c in ("gps_vn_mps", "gps_ve_mps", "gps_vd_mps") if getattr(flight, c) is not None}
    return dataclasses.replace(flight, **out)


def yaw_rate_rps(flight, result, smooth_s=1.0):
    """Body yaw rate r = ψ̇ cos φ, rad/s, and V_t, m/s, from the air-relative GPS velocity.

    ψ is the heading of V_g − W (W: the fitted wind), smoothed over `smooth_s` (the GPS is held
    at its own rate); the bank of a coordinated turn, tan φ = V ψ̇ / g.
    """
    wn, we = wind_vector_mps(result.value("wind_speed_mps"), result.value("wind_from_deg"))
    an, ae = flight.gps_vn_mps - wn, flight.gps_ve_mps - we
    psi = np.unwrap(np.arctan2(ae, an))
    dt = float(np.median(np.diff(flight.time_s)))
    width = max(1, round(smooth_s / dt))
    psi = np.convolve(psi, np.ones(width) / width, mode="same") if width > 1 else psi
    psi_dot = np.gradient(psi, flight.time_s)
    if width > 1:                               # the edges of "same" are half windows
        psi_dot[:width] = psi_dot[width]
        psi_dot[-width:] = psi_dot[-width - 1]
    tas = np.hypot(an, ae)
    return psi_dot / np.sqrt(1.0 + (tas * psi_dot / G0_MPS2) ** 2), tas


def lever_arm_error(flight, result, arm_m):
    """A probe at y = arm_m (right wing +) sees V_t − r y: q_ci scaled by (1 − r y / V_t)²."""
    r, tas = yaw_rate_rps(flight, result)
    return dataclasses.replace(flight, qci_pa=flight.qci_pa * (1.0 - r * arm_m / tas) ** 2)


def lever_arm_corrected(flight, result, arm_m):
    """`flight` corrected for a probe at y = arm_m: q_ci / (1 − r y / V_t)², the arm recorded
    in its `reading` (``probe_arm_m``); r and V_t from `result`'s wind (`yaw_rate_rps`)."""
    r, tas = yaw_rate_rps(flight, result)
    reading = {**(getattr(flight, "reading", None) or {}), "probe_arm_m": float(arm_m)}
    return dataclasses.replace(flight, qci_pa=flight.qci_pa / (1.0 - r * arm_m / tas) ** 2,
                               reading=reading)


def static_pressure_error(flight, result, dp_pa):
    """The static transducer dp_pa high: p_s + dp and the density made of it, ρ ∝ p_s."""
    t = static_temperature_of(flight)
    ps = flight.ps_pa if flight.ps_pa is not None else flight.rho_kgm3 * R_AIR_JKGK * t
    out = {"rho_kgm3": flight.rho_kgm3 * (ps + dp_pa) / ps}
    if flight.ps_pa is not None:
        out["ps_pa"] = flight.ps_pa + dp_pa
    return dataclasses.replace(flight, **out)


def qc_scale_error(flight, result, scale):
    return dataclasses.replace(flight, qci_pa=flight.qci_pa * (1.0 + scale))


def qc_offset_error(flight, result, offset_pa):
    return dataclasses.replace(flight, qci_pa=flight.qci_pa + offset_pa)


PERTURBATIONS = {"oat": oat_error, "humidity": humidity_error,
                 "gps_latency": gps_latency_error, "probe_lever_arm": lever_arm_error,
                 "qc_scale": qc_scale_error, "qc_offset": qc_offset_error,
                 "static_pressure": static_pressure_error}


def inputs_from_options(**options):
    """`BudgetInputs` from keyword options, refusing an unknown name (PitotcalError)."""
    names = {f.name for f in dataclasses.fields(BudgetInputs)}
    unknown = sorted(set(options) - names)
    if unknown:
        raise PitotcalError(f"unknown budget input {unknown[0]!r}; known: "
                            f"{', '.join(sorted(names))}", param=unknown[0])
    return BudgetInputs(**{k: v for k, v in options.items() if v is not None}).checked()

