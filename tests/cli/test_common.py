"""cli.common: the output checks the commands share."""

import os

import pytest

from pitotcal.cli.common import check_distinct, check_output
from pitotcal.core.errors import PitotcalError


def test_an_output_hard_linked_to_the_input_is_refused(tmp_path):
    flight = tmp_path / "flight.csv"
    flight.write_text("x")
    os.link(flight, tmp_path / "r.json")
    with pytest.raises(PitotcalError, match="would overwrite the input flight file"):
        check_output("--json", tmp_path / "r.json", flight, "flight file")


def test_two_outputs_at_one_path_are_refused(tmp_path):
    check_distinct({"--json": tmp_path / "a.json", "--plot": tmp_path / "a.png", "-x": None})
    with pytest.raises(PitotcalError, match="--plot .*same file as --json"):
        check_distinct({"--json": tmp_path / "a.png", "--plot": tmp_path / "./a.png"})
