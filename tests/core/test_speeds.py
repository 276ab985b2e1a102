"""The speed law of "KCAS" (pitotcal.core.speeds) against an independent implementation of the
standard atmosphere and airspeeds (flightcondition)."""

import numpy as np
import pytest
from standard_air import reference

from pitotcal.core.errors import PitotcalError
from pitotcal.core.speeds import (
    cas_from_tas_mps,
    qc_from_tas_isa_pa,
    qc_slope_per_tas,
    tas_from_cas_mps,
    tas_from_qc_mps,
)
from pitotcal.core.units import FT_TO_M, isa_density_kgm3, kt_to_mps, mps_to_kt

pytestmark = pytest.mark.filterwarnings("ignore::DeprecationWarning")   # pint, in flightcondition


@pytest.mark.parametrize("alt_ft, keas, kcas", [(10000.0, 260.0, 262.2), (25000.0, 250.0, 257.3)])
def test_the_equivalent_airspeed_of_the_old_law_is_not_the_cas(alt_ft, keas, kcas):
    """The numbers the EAS-for-KCAS law got wrong: 260 KEAS at 10,000 ft is 262.2 KCAS."""
    alt_m = alt_ft * FT_TO_M
    tas = kt_to_mps(keas) * np.sqrt(1.225 / isa_density_kgm3(alt_m))
    assert float(mps_to_kt(cas_from_tas_mps(tas, alt_m))) == pytest.approx(kcas, abs=0.05)
    ref = reference(alt_m, EAS=keas)
    assert float(mps_to_kt(cas_from_tas_mps(ref.TAS.to("m/s").magnitude, alt_m))) == \
        pytest.approx(ref.CAS.to("knots").magnitude, abs=0.01)


@pytest.mark.parametrize("alt_ft", [-1000.0, 800.0, 10000.0, 25000.0, 36000.0])
def test_cas_and_tas_match_flightcondition(alt_ft):
    alt_m = alt_ft * FT_TO_M
    kcas = np.linspace(60.0, 300.0, 9)
    ref = reference(alt_m, CAS=kcas)
    tas_kt = mps_to_kt(tas_from_cas_mps(kt_to_mps(kcas), alt_m))
    np.testing.assert_allclose(tas_kt, ref.TAS.to("knots").magnitude, atol=0.01)
    np.testing.assert_allclose(mps_to_kt(cas_from_tas_mps(kt_to_mps(tas_kt), alt_m)), kcas,
                               atol=1e-9)
    np.testing.assert_allclose(qc_from_tas_isa_pa(kt_to_mps(tas_kt), alt_m),
                               ref.q_c.to("Pa").magnitude, rtol=1e-4)


def test_inverse_and_slope():
    alt_m, tas = 3048.0, np.array([40.0, 90.0, 150.0])
    qc = qc_from_tas_isa_pa(tas, alt_m)
    np.testing.assert_allclose(tas_from_qc_mps(qc, alt_m), tas, rtol=1e-12)
    step = 1e-4
    numeric = (qc_from_tas_isa_pa(tas + step, alt_m) - qc_from_tas_isa_pa(tas - step, alt_m)) / (
        2 * step)
    np.testing.assert_allclose(qc_slope_per_tas(tas, alt_m), numeric, rtol=1e-8)


def test_altitude_outside_the_isa_is_refused():
    with pytest.raises(PitotcalError, match="pressure_altitude_m 33000 is outside the ISA"):
        tas_from_cas_mps(50.0, 33000.0)


def test_a_negative_cas_keeps_its_sign():
    from pitotcal.core.speeds import tas_from_cas_mps

    tas = tas_from_cas_mps(np.array([10.0, -10.0]), 3000.0)
    assert tas[0] > 10.0 and tas[1] == -tas[0]
