"""The report's aircraft TOML: each bad file refused in one line naming the key (exit 2), the
good ones shown as before."""

import json
import re

import pytest
from reportfixtures import result_json

from pitotcal.cli import main
from pitotcal.core.errors import PitotcalError
from pitotcal.estimation.reporting.aircraft_file import read_aircraft

BAD = [
    ('[aircraft]\nregistraton = "D-EABC"\n', "key aircraft.registraton: unknown; did you mean "
                                             "aircraft.registration?"),
    ('[aircaft]\ntype = "DR400"\n', "key aircaft: unknown table; did you mean [aircraft]?"),
    ('[test]\npilott = "P"\n', "key test.pilott: unknown; did you mean test.pilot?"),
    ('registration = "D-EABC"\n', "key registration: outside a table; put it under [aircraft]"),
    ('[aircraft]\ntype = ["DR400"]\n', "key aircraft.type: an array, expected text, a number"),
    ('[aircraft]\nweight = true\n', "key aircraft.weight: true/false, expected text"),
    ('[aircraft]\nconfiguration = {flaps = 10}\n', "key aircraft.configuration: a table"),
    ("[aircraft]\nweight = nan\n", "key aircraft.weight: nan is not a finite number"),
    ("[aircraft]\nweight = -inf\n", "key aircraft.weight: -inf is not a finite number"),
    ("[aircraft]\nweight = -1050\n", "key aircraft.weight: -1050 is not a weight"),
    ("[aircraft]\nweight = 0\n", "key aircraft.weight: 0 is not a weight"),
    ("[test]\nvne_kt = -163\n", "key test.vne_kt: -163 is a negative speed"),
    ("[test]\nwind_speed = -5.0\n", "key test.wind_speed: -5 is a negative speed"),
    ("[test]\nspeeds_kias = [60, -70]\n", "key test.speeds_kias[1]: -70 is a negative speed"),
    ("[test.wind]\nspeed_kt = nan\n", "key test.wind.speed_kt: nan is not a finite number"),
    ("[aircraft]\ncg = inf\n", "key aircraft.cg: inf is not a finite number"),
]


@pytest.mark.parametrize("text, words", BAD, ids=[w.split(":")[0] for _, w in BAD])
def test_a_bad_aircraft_file_is_refused_naming_the_key(tmp_path, text, words):
    path = tmp_path / "a.toml"
    path.write_text(text)
    with pytest.raises(PitotcalError, match=r"`aircraft_path` .*a\.toml: ") as err:
        read_aircraft(path)
    assert words in str(err.value)


@pytest.mark.parametrize("text, words", BAD[::4], ids=[w.split(":")[0] for _, w in BAD[::4]])
def test_report_says_it_in_one_line_with_the_flag(tmp_path, capsys, text, words):
    res, toml = tmp_path / "r.json", tmp_path / "a.toml"
    res.write_text(json.dumps(result_json()))
    toml.write_text(text)
    code = main(["report", str(res), "-o", str(tmp_path / "r.html"), "--aircraft", str(toml)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and "Traceback" not in err, err
    assert err.startswith(f"pitotcal report: --aircraft {toml}: {words}"), err
    assert not (tmp_path / "r.html").exists() and toml.read_text() == text


def test_good_files_are_shown_whole(tmp_path):
    path = tmp_path / "a.toml"
    path.write_text('[aircraft]\ntype = "DR400"\nweight = 1050\ncg = -0.02\n'
                    '[test]\ndate = 2026-05-04\nfuel = "full"\nvne_kt = 163\nballast = true\n'
                    'pilot_notes = "calm"\n')
    rows = read_aircraft(path)
    assert rows == [("Aircraft", "DR400"), ("Weight", "1050"), ("Centre of gravity", "-0.02"),
                    ("Test date", "2026-05-04"), ("test.fuel", "full"), ("test.vne_kt", "163"),
                    ("test.ballast", "True"), ("test.pilot_notes", "calm")]


def test_a_known_key_with_a_prefix_or_suffix_is_an_extra_key(tmp_path):
    """`weight_kg`, `serial_no`, `copilot`: keys of their own, shown, not misspellings."""
    path = tmp_path / "a.toml"
    path.write_text('[aircraft]\nweight_kg = 1050\nserial_no = "S1"\n[test]\ncopilot = "B"\n')
    assert [name for name, _ in read_aircraft(path)] == [
        "aircraft.weight_kg", "aircraft.serial_no", "test.copilot"]


@pytest.mark.parametrize("text, message", [
    ('[aircraft]\nconfiguration = "landng"\n',
     "key aircraft.configuration: 'landng' is not one of cruise, takeoff, approach, landing; "
     "did you mean 'landing'?"),
    ('[aircraft]\nconfiguration = "crusie"\n',
     "key aircraft.configuration: 'crusie' is not one of cruise, takeoff, approach, landing; "
     "did you mean 'cruise'?"),
    ("[aircraft]\nvs0_kcas = 0\n", "key aircraft.vs0_kcas: 0 is not a speed"),
    ('[aircraft]\nvs1_kcas = "55"\n', "key aircraft.vs1_kcas: '55' is not a speed"),
    ("[aircraft]\nvs1_kcs = 55\n", "key aircraft.vs1_kcs: unknown; did you mean "
                                   "aircraft.vs1_kcas?"),
])
def test_rule_speeds_and_configuration_refused_naming_the_key(tmp_path, text, message):
    from pitotcal.estimation.reporting.aircraft_file import aircraft_rule

    path = tmp_path / "a.toml"
    path.write_text(text)
    with pytest.raises(PitotcalError, match=re.escape(message)):
        aircraft_rule(path)


def test_rule_speeds_read_and_free_text_configuration_kept(tmp_path):
    from pitotcal.estimation.reporting.aircraft_file import aircraft_rule

    path = tmp_path / "a.toml"
    path.write_text('[aircraft]\nconfiguration = "Landing"\nvs0_kcas = 47\nvs1_kcas = 55.5\n')
    assert aircraft_rule(path) == {"configuration": "landing",
                                   "speeds_kcas": {"V_S0": 47.0, "V_S1": 55.5}}
    assert ("V_S1 (KCAS)", "55.5") in read_aircraft(path)
    path.write_text('[aircraft]\nconfiguration = "flaps 10, gear down"\nvs0_kcas = 47\n')
    assert aircraft_rule(path)["configuration"] is None
    assert ("Configuration", "flaps 10, gear down") in read_aircraft(path)


def test_cli_configuration_choices_are_the_rules():
    from pitotcal.cli.report import CONFIGURATIONS
    from pitotcal.estimation.reporting import regulations

    assert CONFIGURATIONS == regulations.CONFIGURATIONS


@pytest.mark.parametrize("speeds, match", [
    # 1.3 V_S1 = 650 KCAS above V_NE 100: the window was reported as "650.0-100.0 KCAS"
    ("vs1_kcas = 500\nvne_kcas = 100", r"aircraft.vs1_kcas 500 and aircraft.vne_kcas 100: V_S1 "
                                       r"must be below V_NE"),
    ("vs0_kcas = 60\nvs1_kcas = 50", r"aircraft.vs0_kcas 60 and aircraft.vs1_kcas 50: V_S0 must "
                                     r"be at most V_S1"),
    ("vsr1_kcas = 120\nvmo_kcas = 120", r"V_SR1 must be below V_MO"),
    ("vsr0_kcas = 90\nvfe_kcas = 80", r"V_SR0 must be below V_FE"),
])
def test_speeds_in_an_impossible_order_are_refused(tmp_path, speeds, match):
    from pitotcal.estimation.reporting.aircraft_file import aircraft_rule

    path = tmp_path / "a.toml"
    path.write_text(f"[aircraft]\n{speeds}\n")
    with pytest.raises(PitotcalError, match=f"`aircraft_path` .*a.toml: keys .*{match}"):
        aircraft_rule(path)


def test_equal_stall_speeds_are_accepted(tmp_path):
    from pitotcal.estimation.reporting.aircraft_file import aircraft_rule

    path = tmp_path / "a.toml"
    path.write_text("[aircraft]\nvs0_kcas = 50\nvs1_kcas = 50\nvfe_kcas = 90\n")
    assert aircraft_rule(path)["speeds_kcas"] == {"V_S0": 50.0, "V_S1": 50.0, "V_FE": 90.0}


def test_the_report_command_offers_the_configurations_the_verdict_knows():
    from pitotcal.cli.report import CONFIGURATIONS as CLI_CONFIGURATIONS
    from pitotcal.estimation.reporting.regulations import CONFIGURATIONS

    assert CLI_CONFIGURATIONS == CONFIGURATIONS
