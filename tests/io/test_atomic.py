"""pitotcal.io.atomic: files are written whole or not at all."""

import json
import os
import stat

import pytest

from pitotcal.io.atomic import atomic_open, save_figure
from pitotcal.io.jsonfile import write_json


def test_a_failed_write_leaves_the_old_file_and_no_temporary(tmp_path):
    path = tmp_path / "r.json"
    write_json(path, {"k1": 0.01})
    with pytest.raises(RuntimeError), atomic_open(path) as fh:
        fh.write('{"half": ')
        raise RuntimeError("cut off")
    assert json.loads(path.read_text()) == {"k1": 0.01}
    assert [p.name for p in tmp_path.iterdir()] == ["r.json"]


def test_the_new_file_replaces_a_hard_link_instead_of_writing_through_it(tmp_path):
    source = tmp_path / "flight.csv"
    source.write_text("time_s\n0\n")
    link = tmp_path / "out.json"
    os.link(source, link)
    write_json(link, {"a": 1})
    assert source.read_text() == "time_s\n0\n"
    assert json.loads(link.read_text()) == {"a": 1}


def test_permissions_are_those_of_a_plain_open(tmp_path):
    plain = tmp_path / "plain.txt"
    plain.write_text("x")
    with atomic_open(tmp_path / "atomic.txt") as fh:
        fh.write("x")
    mode = stat.S_IMODE
    assert mode((tmp_path / "atomic.txt").stat().st_mode) == mode(plain.stat().st_mode)


def test_save_figure_takes_the_format_from_the_name(tmp_path):
    from matplotlib.figure import Figure

    fig = Figure()
    fig.subplots().plot([0, 1])
    save_figure(fig, tmp_path / "f.svg")
    save_figure(fig, tmp_path / "f.png", dpi=50)
    assert (tmp_path / "f.svg").read_text().lstrip().startswith("<?xml")
    assert (tmp_path / "f.png").read_bytes()[:4] == b"\x89PNG"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["f.png", "f.svg"]
