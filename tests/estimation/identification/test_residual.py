"""The residual and the objective: one set of lines for numpy and CasADi, graph size free of N."""

import casadi as ca
import numpy as np
import pytest
from pitotcal.estimation.identification.oe import objective_function
from pitotcal.estimation.identification.residual import (
    residual,
    residual_function,
    residual_terms,
    sensitivities,
)
from pitotcal.estimation.identification.unknowns import theta_scales

from pitotcal.core.models import get_model


def _data(n, has_vd, seed=0):
    rng = np.random.default_rng(seed)
    return {"qci": rng.uniform(800.0, 1600.0, n), "vn": rng.uniform(-50.0, 50.0, n),
            "ve": rng.uniform(-50.0, 50.0, n), "rho": rng.uniform(1.1, 1.2, n),
            "vd2": rng.uniform(0.0, 4.0, n) if has_vd else 0.0, "c_eiv": 0.02}


@pytest.mark.parametrize("has_vd", [False, True])
@pytest.mark.parametrize("name", ["constant", "linear", "inverse"])
def test_casadi_residual_equals_numpy(name, has_vd):
    model = get_model(name)
    theta = np.array([0.02, 1e-5 if name == "linear" else -15.0][: len(model.params)] + [3.0, -4.0])
    d = _data(50, has_vd)
    fn = residual_function(model, 50, has_vd)
    assert fn.name_in() == ["theta", "qci", "vn", "ve", "rho", "vd2", "c_eiv"]
    assert fn.name_out() == ["r", "a", "tas_sq"]
    got = fn(theta=theta, **d)
    want = residual_terms(model, theta, d["qci"], d["vn"], d["ve"], d["rho"], d["vd2"], d["c_eiv"])
    for key, value in zip(("r", "a", "tas_sq"), want):
        assert np.allclose(np.asarray(got[key]).ravel(), value, rtol=1e-14, atol=1e-12)


def test_objective_is_the_corrected_score():
    model, n = get_model("inverse"), 40
    d = _data(n, True, seed=1)
    theta = np.array([0.02, -15.0, 3.0, -4.0])
    var_v, weight = 0.01, 1e-2
    fn = objective_function(model, n, True)
    assert fn.name_in() == ["x", "qci", "vn", "ve", "rho", "vd2",
                            "c_eiv", "pen_a", "pen_b", "weight"]
    got = float(fn(x=theta / theta_scales(model), qci=d["qci"], vn=d["vn"], ve=d["ve"],
                   rho=d["rho"], vd2=d["vd2"], c_eiv=3 * var_v, pen_a=4 * var_v,
                   pen_b=6 * var_v ** 2, weight=weight)["J"])
    r, a, v2 = residual_terms(model, theta, d["qci"], d["vn"], d["ve"], d["rho"], d["vd2"], 3 * var_v)
    want = weight / n * np.sum(r ** 2 - a ** 2 * (4 * var_v * v2 - 6 * var_v ** 2))
    assert got == pytest.approx(want, rel=1e-12)


def test_graph_size_does_not_grow_with_n():
    model = get_model("inverse")
    # n = 12, not 10: the merged graph shares a constant 10 with 1/n there (one node fewer)
    small, large = (objective_function(model, n, False).n_nodes() for n in (12, 1_000_000))
    assert small == large < 60


def test_sensitivities_match_casadi_jacobian():
    model, n = get_model("inverse"), 30
    d = _data(n, True, seed=2)
    theta = np.array([0.02, -15.0, 3.0, -4.0])
    fn = residual_function(model, n, True)
    sym = ca.MX.sym("theta", 4)
    r = fn(sym, d["qci"], d["vn"], d["ve"], d["rho"], d["vd2"], d["c_eiv"])[0]
    jac = ca.Function("j", [sym], [ca.jacobian(r, sym)])(theta)
    got = sensitivities(model, theta, d["qci"], d["vn"], d["ve"], d["rho"], d["vd2"], d["c_eiv"])
    assert np.allclose(got, np.asarray(jac), rtol=1e-6, atol=1e-9)


@pytest.mark.parametrize("has_vd", [False, True])
def test_numpy_residual_is_the_first_term(has_vd):
    model, d = get_model("linear"), _data(30, has_vd, seed=3)
    theta = np.array([0.02, 1e-5, 3.0, -4.0])
    args = (d["qci"], d["vn"], d["ve"], d["rho"], d["vd2"] if has_vd else None, d["c_eiv"])
    np.testing.assert_array_equal(residual(model, theta, *args),
                                  residual_terms(model, theta, *args)[0])


def _air(d, seed=4):
    """Compressible air data for `_data`: total pressure (Pa) and static temperature (K)."""
    rng = np.random.default_rng(seed)
    n = d["qci"].size
    return rng.uniform(60000.0, 100000.0, n), rng.uniform(250.0, 290.0, n)


@pytest.mark.parametrize("kind", ["compressible", "reference"])
@pytest.mark.parametrize("name", ["constant", "inverse"])
def test_compressible_residual_casadi_numpy_and_jacobian(name, kind):
    """The compressible residual (total pressure, or a reference static pressure): CasADi
    graph = numpy lines; the closed-form sensitivities (local slope a) = CasADi's Jacobian."""
    from pitotcal.estimation.identification.residual import AIR_CHANNELS, ReferenceAir, TotalAir

    model, n = get_model(name), 30
    d = _data(n, True, seed=5)
    pt, oat = _air(d)
    air = TotalAir(pt, oat) if kind == "compressible" else ReferenceAir(0.95 * pt, oat)
    theta = np.array([0.02, -15.0][: len(model.params)] + [3.0, -4.0])
    fn = residual_function(model, n, True, kind)
    assert fn.name_in() == ["theta", "qci", "vn", "ve", *AIR_CHANNELS[kind], "vd2", "c_eiv"]
    args = (d["qci"], d["vn"], d["ve"], air, d["vd2"], d["c_eiv"])
    pt = air[0]
    want = residual_terms(model, theta, *args)
    got = fn(theta, d["qci"], d["vn"], d["ve"], pt, oat, d["vd2"], d["c_eiv"])
    for g, w in zip(got, want):
        np.testing.assert_allclose(np.asarray(g).ravel(), w, rtol=1e-12, atol=1e-9)
    sym = ca.MX.sym("theta", theta.size)
    r = fn(sym, d["qci"], d["vn"], d["ve"], pt, oat, d["vd2"], d["c_eiv"])[0]
    jac = np.asarray(ca.Function("j", [sym], [ca.jacobian(r, sym)])(theta))
    np.testing.assert_allclose(sensitivities(model, theta, *args), jac, rtol=1e-8, atol=1e-9)
    # a = dq_ci/dV_t^2: the wind column is -a dV_t^2/dwind_n = 2 a (V_gn - wind_n)
    np.testing.assert_allclose(jac[:, -2], 2 * want[1] * (d["vn"] - theta[-2]), rtol=1e-8)
    np.testing.assert_array_equal(residual(model, theta, *args), want[0])


@pytest.mark.parametrize("air_data", ["incompressible", "compressible"])
def test_spread_weights_are_the_spread_gradient(air_data):
    """The instrumental-variable wind rows use -1/2 d(spread)/d(wind) (`spread_weights`):
    checked against CasADi's derivative of the objective's own spread term."""
    from pitotcal.estimation.identification.residual import Channels, spread_weights

    model, n, var_v = get_model("inverse"), 25, 0.004
    d = _data(n, True, seed=6)
    pt, oat = _air(d) if air_data == "compressible" else (None, None)
    ch = Channels(qci=d["qci"], vn=d["vn"], ve=d["ve"], rho=d["rho"], vd2=d["vd2"],
                  sigma_v=var_v ** 0.5, var_v=var_v, n_comp=3, pt=pt, oat=oat)
    theta = np.array([0.02, -15.0, 3.0, -4.0])
    fn = residual_function(model, n, True, air_data)
    sym = ca.MX.sym("theta", 4)
    air = [d["rho"]] if pt is None else [pt, oat]
    _, a, v2 = fn(sym, d["qci"], d["vn"], d["ve"], *air, d["vd2"], ch.c_eiv)
    spread = ca.dot(a * a, 4 * var_v * v2 - 2 * 3 * var_v ** 2)
    grad = np.asarray(ca.Function("g", [sym], [ca.gradient(spread, sym)])(theta)).ravel()
    c, w = spread_weights(model, theta, ch)
    got = [c * np.sum(w * (d["vn"] - theta[-2])), c * np.sum(w * (d["ve"] - theta[-1]))]
    np.testing.assert_allclose(got, -0.5 * grad[-2:], rtol=1e-9)


def test_compressible_graph_size_does_not_grow_with_n():
    model = get_model("inverse")
    small, large = (objective_function(model, n, False, "compressible").n_nodes()
                    for n in (12, 1_000_000))
    # 85 nodes with the Rayleigh branch above Mach 1 (if_else evaluates both branches; 125
    # before the objective's common subexpressions were merged); 71 when it was isentropic only
    assert small == large < 90
