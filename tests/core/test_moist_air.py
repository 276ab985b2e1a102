"""Temperature and humidity inputs (core.moist_air) against tables, psychrolib and truth."""

import numpy as np
import pytest

from pitotcal.core import airdata as ad
from pitotcal.core import moist_air as ma
from pitotcal.core.errors import FlightDataError, PitotcalError
from pitotcal.core.flight import Flight
from pitotcal.core.units import R_AIR_JKGK, density_kgm3


@pytest.mark.parametrize("t_c, table_pa", [(0.0, 611.2), (10.0, 1228.1), (20.0, 2338.8),
                                           (30.0, 4246.0), (40.0, 7384.9)])
def test_saturation_against_table(t_c, table_pa):
    # Wexler (1976) values over water, as tabulated in the WMO/CIMO guide: AE 1996 within 0.4 %
    assert ma.saturation_vapour_pressure_pa(t_c + 273.15) == pytest.approx(table_pa, rel=4e-3)


def test_saturation_and_moist_density_against_psychrolib():
    psy = pytest.importorskip("psychrolib")
    psy.SetUnitSystem(psy.SI)
    for t_c in (0.0, 15.0, 25.0, 35.0):
        t_k, p, rh = t_c + 273.15, 90000.0, 0.7
        assert ma.saturation_vapour_pressure_pa(t_k) == pytest.approx(psy.GetSatVapPres(t_c),
                                                                       rel=4e-3)
        w = psy.GetHumRatioFromRelHum(t_c, rh, p)
        # psychrolib: moist-air density = (1 + W) / specific volume, with its own R_da
        rho_ref = psy.GetMoistAirDensity(t_c, w, p)
        assert ma.moist_density_kgm3(p, t_k, 100 * rh) == pytest.approx(rho_ref, rel=1e-3)


def test_virtual_temperature_worked_example():
    # 30 °C, 1000 hPa, saturated: e = 42.4 hPa, T_v = T / (1 - 0.378 e/p) = 308.0 K
    tv = ma.virtual_temperature_k(303.15, 100000.0, 100.0)
    assert tv == pytest.approx(303.15 / (1 - 0.378 * 4240.6 / 1e5), abs=0.02)
    assert ma.virtual_temperature_k(288.15, 101325.0, 0.0) == 288.15
    # humid air is lighter: 1.6 % at 30 °C saturated, as the issue quotes (~1 %)
    drop = 1 - ma.moist_density_kgm3(1e5, 303.15, 100.0) / density_kgm3(1e5, 303.15)
    assert 0.015 < drop < 0.017


@pytest.mark.parametrize("mach, recovery", [(0.15, 1.0), (0.45, 1.0), (0.45, 0.95)])
def test_static_from_total_temperature(mach, recovery):
    ts, ps = 250.0, 60000.0
    tt = ts * (1 + recovery * 0.2 * mach ** 2)
    qc = ad.qc_from_mach_pa(mach, ps)
    assert ma.static_temperature_k(tt, qc, ps, recovery) == pytest.approx(ts, rel=1e-12)


def _flight(**air):
    n = 20
    return Flight(time_s=np.arange(n, dtype=float), qci_pa=np.full(n, 3000.0),
                  gps_vn_mps=np.full(n, 60.0), gps_ve_mps=np.zeros(n),
                  rho_kgm3=np.full(n, 1.0), **air)


def test_with_static_air_recovers_truth():
    n, ps, ts, rh = 20, np.full(20, 80000.0), np.full(20, 275.0), np.full(20, 60.0)
    mach = ad.mach_from_qc(3000.0, 80000.0)
    tat = ts * (1 + 0.98 * 0.2 * mach ** 2)
    raw = _flight(ps_pa=ps, tat_k=tat, rh_pct=rh)
    out = ma.with_static_air(raw, temp_recovery=0.98)
    tv = ts / (1 - 0.6 * ma.saturation_vapour_pressure_pa(ts) / ps * (1 - 0.622))
    assert out.oat_k == pytest.approx(tv, rel=1e-12)           # humid: the virtual temperature
    assert out.rho_kgm3 == pytest.approx(ps / (R_AIR_JKGK * tv), rel=1e-12)
    # another recovery factor converts the raw total temperature with it
    other = ma.with_static_air(raw, temp_recovery=1.0)
    assert other.oat_k == pytest.approx(ma.virtual_temperature_k(
        tat / (1 + 0.2 * mach ** 2), ps, 60.0), rel=1e-12)
    # --rh-percent overrides the column; dry: oat_k is the static temperature itself
    dry = ma.with_static_air(raw, temp_recovery=0.98, rh_pct=0.0)
    assert dry.oat_k == pytest.approx(ts, rel=1e-12)
    assert dry.rho_kgm3 == pytest.approx(ps / (R_AIR_JKGK * ts), rel=1e-12)
    assert n == out.n


def test_air_data_is_made_once_when_read(tmp_path):
    """read_flight makes the air data with the user's recovery factor and humidity, once; a
    flight so read refuses a second conversion (which would apply the humidity twice)."""
    from pitotcal.io import read_flight, write_flight_csv

    ps, ts = np.full(20, 90000.0), np.full(20, 300.0)
    path = write_flight_csv(_flight(ps_pa=ps, oat_k=ts, rh_pct=np.full(20, 70.0)),
                            tmp_path / "humid.csv")
    once = read_flight(path)
    assert once.oat_k == pytest.approx(ma.virtual_temperature_k(ts, ps, 70.0), rel=1e-10)
    assert once.reading == {"start_s": None, "end_s": None, "oat_k": None,
                            "temp_recovery": 1.0, "rh_pct": None,
                            "oat_source": "oat_k"}
    with pytest.raises(PitotcalError, match="air data was made when it was read"):
        ma.with_static_air(once, rh_pct=0.0)
    dry = read_flight(path, rh_pct=0.0)
    assert dry.oat_k == pytest.approx(ts, rel=1e-10) and dry.reading["rh_pct"] == 0.0


def test_with_static_air_untouched_and_refusals():
    plain = _flight()
    assert ma.with_static_air(plain) is plain
    with pytest.warns(UserWarning, match="tat_k needs the static pressure .* ignored"):
        ignored = ma.with_static_air(_flight(tat_k=np.full(20, 280.0)))
    assert ignored.rho_kgm3 == pytest.approx(1.0) and "ignored" in ignored.warnings[-1]
    with pytest.raises(FlightDataError, match="humidity needs the static pressure"):
        ma.with_static_air(_flight(), rh_pct=50.0)
    with pytest.raises(PitotcalError, match="temp_recovery"):
        ma.with_static_air(plain, temp_recovery=1.5)
    with pytest.raises(PitotcalError, match="rh_percent"):
        ma.with_static_air(plain, rh_pct=120.0)
    with pytest.raises(FlightDataError, match="column rh_pct, row 3"):
        rh = np.full(20, 50.0)
        rh[2] = 130.0
        ma.with_static_air(_flight(ps_pa=np.full(20, 9e4), oat_k=np.full(20, 280.0), rh_pct=rh))


def test_a_flight_written_after_reading_reads_back_the_same(tmp_path):
    """A converted flight written out carries its virtual oat_k (`# oat_k_is`): read again,
    the humidity is not applied twice (the density stays the first read's)."""
    import pitotcal

    n = 200
    ang = np.linspace(0.0, 2 * np.pi, n)
    rows = ["time_s,qc_pa,gps_vn_mps,gps_ve_mps,ps_pa,oat_k,rh_pct"]
    rows += [f"{0.1 * i:.2f},{1500 + 100 * np.sin(a):.3f},{50 * np.cos(a):.4f},"
             f"{50 * np.sin(a):.4f},95000,303.15,80" for i, a in enumerate(ang)]
    (tmp_path / "humid.csv").write_text("\n".join(rows) + "\n")
    first = pitotcal.read_flight(tmp_path / "humid.csv")
    pitotcal.write_flight_csv(first, tmp_path / "again.csv")
    again = pitotcal.read_flight(tmp_path / "again.csv")
    np.testing.assert_allclose(again.rho_kgm3, first.rho_kgm3, rtol=1e-8)
    np.testing.assert_allclose(again.oat_k, first.oat_k, rtol=1e-8)
    with pytest.raises(PitotcalError, match="virtual temperature"):
        pitotcal.read_flight(tmp_path / "again.csv", rh_pct=50.0)
