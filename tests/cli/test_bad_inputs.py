"""The counted bad-input suite: every command fed broken, odd and hostile inputs, in process.

Each case runs `pitotcal.cli.main` under a time limit and must end in one line on stderr and a
non-zero exit status (2, or 3 where the data cannot separate the wind), never a traceback,
never a hang, never exit 0 on a garbage calibration or result JSON; where the input is usable
(a log truncated mid-record, a window past the end) the case says which exit statuses it
accepts. Every input file's checksum is the same after each case as before the suite.
The small fixture files are made once per module (a 60-s flight at 10 Hz).
"""

import hashlib
import json
import os
import signal
import sys
import threading
import warnings
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pytest
from plans import circle_plan
from reportfixtures import setting

from pitotcal.cli import build_parser, main
from pitotcal.io.plan_csv import write_plan

LIMIT_S = 20                 # per case: a case that takes longer is a hang
MIN_CASES = 300


@dataclass
class Case:
    """One hostile run: `argv` with ``{name}`` fields filled from the fixture files.

    `codes`: the exit statuses accepted (a refusal by default); `words`: what its one error
    line must say; `stdin`: bytes on standard input; `fifo`: what a thread writes into the
    FIFO the case reads (a `_stream_data` key, or a fixture log such as ``log_bin``);
    `extra`: ``link`` (an output made a link to an input first), ``stdin_file`` (a fixture
    file on standard input).
    """

    id: str
    argv: list
    codes: tuple = (2,)
    words: tuple = ()
    stdin: bytes | None = None
    fifo: str | None = None
    skip: str = ""
    extra: dict = field(default_factory=dict)


# --- fixture files ---------------------------------------------------------------------------

FLIGHT_COLUMNS = ("time_s", "qc_pa", "gps_vn_mps", "gps_ve_mps", "rho_kgm3", "gps_vd_mps",
                  "alt_m", "ps_pa", "oat_k")
PA = {"hPa": 100.0, "kPa": 1000.0, "psi": 6894.757, "inH2O": 249.089, "mmH2O": 9.80665,
      "inHg": 3386.389, "mmHg": 133.3224}
MPS = {"kt": 1852.0 / 3600.0, "kmh": 1.0 / 3.6, "mph": 0.44704}
CELLS = {"nan": "nan", "inf": "inf", "minf": "-inf", "1e200": "1e200", "text": "abc",
         "empty": ""}


def _csv_parts(path):
    lines = path.read_text().splitlines()
    head = next(i for i, line in enumerate(lines) if line.startswith("time_s"))
    return lines[:head], lines[head].split(","), [r.split(",") for r in lines[head + 1:]]


def _write_csv(path, comments, header, rows):
    path.write_text("\n".join(comments + [",".join(header)] + [",".join(r) for r in rows])
                    + "\n")
    return path


def _cells(root, flight):
    """A column's cells replaced by a bad value in every fifth row (too many to drop)."""
    comments, header, rows = _csv_parts(flight)
    for column in FLIGHT_COLUMNS:
        j = header.index(column)
        for name, cell in CELLS.items():
            bad = [list(r) for r in rows]
            for r in bad[::5]:
                r[j] = cell
            _write_csv(root / f"cell_{column}_{name}.csv", comments, header, bad)


def _units(root, flight):
    """One column in another unit (the whole column converted)."""
    comments, header, rows = _csv_parts(flight)
    data = np.array([[float(c) for c in r] for r in rows])
    col = {c: header.index(c) for c in header}

    def write(name, edit):
        d = data.copy()
        edit(d)
        _write_csv(root / f"unit_{name}.csv", comments, header,
                   [[f"{v:.9g}" for v in r] for r in d])

    for unit, k in PA.items():
        write(f"qc_{unit}", lambda d, k=k: d.__setitem__((slice(None), col["qc_pa"]),
                                                         d[:, col["qc_pa"]] / k))
        if unit not in ("inH2O", "mmH2O"):
            write(f"ps_{unit}", lambda d, k=k: d.__setitem__((slice(None), col["ps_pa"]),
                                                             d[:, col["ps_pa"]] / k))
    for unit, k in MPS.items():
        def gps(d, k=k):
            for c in ("gps_vn_mps", "gps_ve_mps"):
                d[:, col[c]] /= k
        write(f"gps_{unit}", gps)
    write("oat_degC", lambda d: d.__setitem__((slice(None), col["oat_k"]),
                                              d[:, col["oat_k"]] - 273.15))
    write("oat_degF", lambda d: d.__setitem__((slice(None), col["oat_k"]),
                                              (d[:, col["oat_k"]] - 273.15) * 1.8 + 32))
    write("rho_lbft3", lambda d: d.__setitem__((slice(None), col["rho_kgm3"]),
                                               d[:, col["rho_kgm3"]] / 16.0185))
    write("time_ms", lambda d: d.__setitem__((slice(None), col["time_s"]),
                                             d[:, col["time_s"]] * 1e3))
    write("time_min", lambda d: d.__setitem__((slice(None), col["time_s"]),
                                              d[:, col["time_s"]] / 60.0))
    write("vd_cms", lambda d: d.__setitem__((slice(None), col["gps_vd_mps"]),
                                            d[:, col["gps_vd_mps"]] * 100.0 + 150.0))


def _missing(root, flight):
    comments, header, rows = _csv_parts(flight)
    for drop in (("time_s",), ("qc_pa",), ("gps_vn_mps",), ("gps_ve_mps",),
                 ("rho_kgm3", "ps_pa"), ("rho_kgm3", "oat_k")):
        keep = [j for j, c in enumerate(header) if c not in drop]
        _write_csv(root / f"missing_{'_'.join(drop)}.csv", comments,
                   [header[j] for j in keep], [[r[j] for j in keep] for r in rows])
    # a header spelt otherwise, duplicated columns, a header only, ten rows
    _write_csv(root / "renamed.csv", comments, [h.upper() for h in header], rows)
    _write_csv(root / "duplicate_column.csv", comments, header + ["qc_pa"],
               [r + [r[1]] for r in rows])
    _write_csv(root / "header_only.csv", comments, header, [])
    _write_csv(root / "five_rows.csv", comments, header, rows[:5])
    _write_csv(root / "constant_time.csv", comments, header,
               [["100.0"] + r[1:] for r in rows])
    _write_csv(root / "reversed_time.csv", comments, header, rows[::-1])
    _write_csv(root / "short_rows.csv", comments, header, [r[:3] for r in rows])
    _write_csv(root / "long_rows.csv", comments, header, [r + r for r in rows])
    _write_csv(root / "semicolons.csv", [], [";".join(header)], [[";".join(r)] for r in rows])


def _broken(root, files):
    """Truncated, corrupt, empty and foreign files of each kind."""
    blob = files["flight"].read_bytes()
    (root / "trunc_header.csv").write_bytes(blob[:blob.index(b"time_s") + 20])
    (root / "utf16.csv").write_bytes(blob.decode().encode("utf-16"))
    (root / "nul.csv").write_bytes(blob[:2000] + b"\0" * 64 + blob[2064:])
    rng = np.random.default_rng(0)
    noise = rng.integers(0, 256, 20000, dtype=np.uint8).tobytes()
    (root / "random.csv").write_bytes(noise)
    (root / "empty.csv").write_bytes(b"")
    (root / "blank.csv").write_bytes(b"\n \n\t\n")
    (root / "bin_as.csv").write_bytes(files["log_bin"].read_bytes())
    (root / "ulg_as.csv").write_bytes(files["log_ulg"].read_bytes())
    for kind in ("bin", "ulg"):
        data = files[f"log_{kind}"].read_bytes()
        for frac in (0.001, 0.05):
            (root / f"trunc{int(frac * 1000)}.{kind}").write_bytes(data[:int(len(data) * frac)])
        (root / f"random.{kind}").write_bytes(noise)
        (root / f"empty.{kind}").write_bytes(b"")
        (root / f"csv_as.{kind}").write_bytes(blob)
        flipped = bytearray(data)
        flipped[:64] = bytes(64)
        (root / f"zeroed_head.{kind}").write_bytes(bytes(flipped))
    (root / "text.log").write_text("FMT, 1, 2, 3\nthis is no log\n")
    (root / "empty.log").write_bytes(b"")
    (root / "ulg_as.bin").write_bytes(files["log_ulg"].read_bytes())
    (root / "bin_as.ulg").write_bytes(files["log_bin"].read_bytes())
    (root / "flight.tlog").write_bytes(noise[:500])
    (root / "binary.toml").write_bytes(Path(sys.executable).resolve().read_bytes()[:4096])


def _results(root, result):
    """Result JSONs that are garbage as a calibration or a report's input."""
    doc = json.loads(result.read_text())
    text = result.read_text()

    def edited(name, edit):
        d = json.loads(text)
        edit(d)
        (root / f"res_{name}.json").write_text(json.dumps(d))

    def deleter(path):
        def edit(d):
            node = d
            for key in path[:-1]:
                node = node[key]
            del node[path[-1]]
        return edit

    raw = {"empty": "", "blank": "  \n", "obj": "{}", "list": "[]", "null": "null", "num": "42",
           "str": '"result"', "nested_list": "[" * 100_000, "nested_obj": '{"a":' * 100_000,
           "truncated": text[:len(text) // 2], "trailing": text + "}",
           "single_quotes": text.replace('"', "'"), "flight_csv": "time_s,qc_pa\n1,2\n"}
    for name, body in raw.items():
        (root / f"res_{name}.json").write_text(body)
    (root / "res_utf16.json").write_bytes(text.encode("utf-16"))
    (root / "res_binary.json").write_bytes(Path(sys.executable).resolve().read_bytes()[:4096])
    k1 = ("parameters", "k1", "value")
    for name, value in (("k1_nan", float("nan")), ("k1_inf", float("inf")), ("k1_1e200", 1e200),
                        ("k1_099", 0.99), ("k1_str", "0.01"), ("k1_null", None),
                        ("k1_list", [0.01]), ("k1_bool", True)):
        edited(name, setting(k1, value))
    edited("no_parameters", deleter(("parameters",)))
    edited("no_k1", deleter(("parameters", "k1")))
    edited("params_list", setting(("parameters",), [1, 2]))
    if "noise_std_pa" in doc:
        edited("noise_zero", setting(("noise_std_pa",), 0.0))
        edited("noise_neg", setting(("noise_std_pa",), -1.0))
    edited("model_unknown", setting(("model",), "cubic"))
    for key in ("rel_std", "std_mps", "ar1", "block_s"):
        if key in doc.get("noise_model", {}):
            edited(f"nm_{key}_nan", setting(("noise_model", key), float("nan")))
            edited(f"nm_{key}_neg", setting(("noise_model", key), -5.0))
    rows = "airspeed_correction"
    if doc.get(rows):
        edited("table_vi_neg", lambda d: d[rows][0].__setitem__("vi_kt", -50.0))
        edited("table_vi_str", lambda d: d[rows][0].__setitem__("vi_kt", "fast"))
        edited("table_dv_nan", lambda d: d[rows][0].__setitem__("dv_kt", float("nan")))
        edited("table_not_list", setting((rows,), {"a": 1}))
        edited("table_rows_str", setting((rows,), ["x", "y"]))
    edited("outer_list", lambda d: None)
    (root / "res_outer_list.json").write_text(json.dumps([doc]))


def _tomls(root):
    bodies = {"syntax": "mass = [1, 2\n", "empty_key": "= 3\n", "deep": "a = " + "[" * 5000,
              "typo": 'aircraft = "T-2"\nregisration = "D-EXYZ"\n',
              "bad_type": 'aircraft = 3\n', "nan_value": "max_speed_kt = nan\n",
              "table": "[aircraft]\nname = 1\n", "utf16": None,
              "weight_list": "[aircraft]\nweight = [1, 2]\n",
              "type_nan": "[aircraft]\ntype = nan\n",
              "misspelt": '[aircraft]\nregistation = "D-EXYZ"\n',
              "date_table": "[test]\ndate = {a = 1}\n",
              "weight_negative": "[aircraft]\nweight = -5\n",
              "speed_negative": "[aircraft]\nmax_speed_kt = -100\n"}
    for name, body in bodies.items():
        if body is None:
            (root / f"ac_{name}.toml").write_bytes('aircraft = "T-2"\n'.encode("utf-16"))
        else:
            (root / f"ac_{name}.toml").write_text(body)


def _plans(root, plan):
    """Plan CSVs with a bad comment value (the simulator's wind) or a bad body."""
    lines = plan.read_text().splitlines()
    head = next(i for i, line in enumerate(lines) if not line.startswith("#"))

    def write(name, new_lines):
        (root / f"plan_{name}.csv").write_text("\n".join(new_lines) + "\n")

    for key, value in (("wind_speed_mps", "nan"), ("wind_speed_mps", "1e9"),
                       ("wind_speed_mps", "abc"), ("wind_speed_mps", "-5"),
                       ("wind_from_deg", "nan"), ("wind_from_deg", "[1, 2]")):
        write(f"{key}_{value[:3]}", [f"# {key}: {value}" if line.startswith(f"# {key}:")
                                     else line for line in lines])
    body = [line.split(",") for line in lines[head + 1:]]
    for name, edit in (("cell_nan", lambda r: r.__setitem__(1, "nan")),
                       ("cell_text", lambda r: r.__setitem__(1, "fast")),
                       ("cas_zero", lambda r: r.__setitem__(lines[head].split(",").index(
                           "cas_mps"), "0"))):
        rows = [list(r) for r in body]
        edit(rows[3])
        write(name, lines[:head + 1] + [",".join(r) for r in rows])
    write("reversed", lines[:head + 1] + lines[head + 1:][::-1])
    write("header_only", lines[:head + 1])
    write("one_row", lines[:head + 2])
    write("no_columns", lines[:head])
    write("short_row", lines[:head + 3] + [lines[head + 3].rsplit(",", 2)[0]])


def _legs(root):
    head = "point,ias_kt,pressure_alt_ft,oat_c,groundspeed_kt,track_deg\n"
    good = ["1,100,3000,10,100,0", "1,100,3000,10,110,120", "1,100,3000,10,90,240",
            "2,120,3000,10,120,0", "2,120,3000,10,130,120", "2,120,3000,10,110,240"]
    (root / "legs.csv").write_text(head + "\n".join(good) + "\n")
    variants = {
        "nan": good[:1] + ["1,nan,3000,10,110,120"] + good[2:],
        "text": good[:1] + ["1,100,3000,10,fast,120"] + good[2:],
        "inf": good[:1] + ["1,100,inf,10,110,120"] + good[2:],
        "1e200": good[:1] + ["1,100,3000,10,1e200,120"] + good[2:],
        "kelvin": [r.replace(",10,", ",283,") for r in good],
        "ias_mps": [",".join([p, str(float(v) * 0.5144)] + rest)
                    for p, v, *rest in (r.split(",") for r in good)],
        "gs_mps": [",".join(c[:4] + [str(float(c[4]) * 0.5144)] + c[5:])
                   for c in (r.split(",") for r in good)],
        "track_rad": [",".join(c[:5] + [str(np.radians(float(c[5])))])
                      for c in (r.split(",") for r in good)],
        "alt_m": [r.replace(",3000,", ",914,") for r in good],
        "two_legs": good[:2],
        "empty_point": [","+ r.split(",", 1)[1] for r in good],
        "negative_ias": [r.replace(",100,3000", ",-100,3000") for r in good],
    }
    for name, rows in variants.items():
        (root / f"legs_{name}.csv").write_text(head + "\n".join(rows) + "\n")
    (root / "legs_no_track.csv").write_text(
        "point,ias_kt,pressure_alt_ft,oat_c,groundspeed_kt\n1,100,3000,10,100\n")
    (root / "legs_header_only.csv").write_text(head)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """{name: path} of every input of the suite, and their checksums before it."""
    from logwriters import write_dataflash_bin, write_tlog, write_ulog

    from pitotcal.io import read_flight

    root = tmp_path_factory.mktemp("bad_inputs")
    out = {"root": root}
    out["plan"] = write_plan(circle_plan(duration_s=60.0), root / "plan.csv")
    out["flight"], out["result"] = root / "flight.csv", root / "result.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert main(["simulate", str(out["plan"]), "-o", str(out["flight"]), "--rate-hz",
                     "10"]) == 0
        assert main(["identify", str(out["flight"]), "--json", str(out["result"])]) == 0
        flight = read_flight(out["flight"])
    out["log_bin"] = write_dataflash_bin(root / "flight.bin", flight) or root / "flight.bin"
    out["log_ulg"] = write_ulog(root / "flight.ulg", flight) or root / "flight.ulg"
    # telemetry logs: one without airspeed, one cut to its first messages
    write_tlog(root / "nodp.tlog", flight, press_diff=False)
    tlog = write_tlog(root / "whole.tlog", flight).read_bytes()
    (root / "trunc.tlog").write_bytes(tlog[:3000])
    _cells(root, out["flight"])
    _units(root, out["flight"])
    _missing(root, out["flight"])
    _broken(root, out)
    _results(root, out["result"])
    _tomls(root)
    _legs(root)
    _plans(root, out["plan"])
    (root / "folder").mkdir()
    (root / "alfa").mkdir()
    (root / "alfa" / "scaled_pressure.csv").write_text("a,b\n1,2\n")
    (root / "folder.csv").mkdir()
    (root / "folder.json").mkdir()
    (root / "aircraft.toml").write_text('aircraft = "T-2"\n')
    (root / "dangling.csv").symlink_to(root / "nowhere.csv")
    (root / "dangling.json").symlink_to(root / "nowhere.json")
    out["sums"] = _checksums(root)
    return out


def _checksums(root):
    return {p.name: hashlib.sha256(p.read_bytes()).hexdigest()
            for p in sorted(root.iterdir()) if p.is_file() and not p.is_symlink()}


# --- the cases -------------------------------------------------------------------------------

# How each command reads a flight, a result JSON or a log given as {src}.
FLIGHT_READERS = {"identify": ["identify", "{src}", "--no-budget", "--json", "{out}/r.json"],
                  "legs": ["legs", "{src}"],
                  "monitor": ["monitor", "{src}", "--calibration", "{result}"]}
RESULT_READERS = {"report": ["report", "{src}", "-o", "{out}/r.html"],
                  "monitor": ["monitor", "{flight}", "--calibration", "{src}"],
                  "plan": ["plan", "--calibration", "{src}", "-o", "{out}/p.csv",
                           "--no-figures"]}
LOG_READERS = {"identify": ["identify", "{src}", "--no-budget"],
               "convert": ["convert", "{src}", "-o", "{out}/c.csv"]}


def _with(template, src):
    return [a.replace("{src}", src) for a in template]


def _flight_cases():
    cases = []
    for column in FLIGHT_COLUMNS:
        for name in CELLS:
            # alt_m is informative only: an unusable cell is a missing altitude, not a bad row
            cases.append(Case(f"identify cell {column}={name}",
                              _with(FLIGHT_READERS["identify"],
                                    f"{{root}}/cell_{column}_{name}.csv"),
                              words=(column,), codes=(0,) if column == "alt_m" else (2,)))
    for command in ("legs", "monitor"):
        for column in ("time_s", "qc_pa", "gps_vn_mps", "ps_pa"):
            for name in ("nan", "text"):
                cases.append(Case(f"{command} cell {column}={name}",
                                  _with(FLIGHT_READERS[command],
                                        f"{{root}}/cell_{column}_{name}.csv"), words=(column,)))
    units = ([f"qc_{u}" for u in PA] + [f"ps_{u}" for u in PA if u not in ("inH2O", "mmH2O")]
             + [f"gps_{u}" for u in MPS] + ["oat_degC", "oat_degF", "rho_lbft3", "time_ms",
                                            "time_min", "vd_cms"])
    for command, template in FLIGHT_READERS.items():
        for unit in units:
            cases.append(Case(f"{command} unit {unit}",
                              _with(template, f"{{root}}/unit_{unit}.csv"),
                              words=("looks like lb/ft^3",) if unit == "rho_lbft3"
                              else ("looks like",)))
    missing = ["missing_time_s", "missing_qc_pa", "missing_gps_vn_mps", "missing_gps_ve_mps",
               "missing_rho_kgm3_ps_pa", "missing_rho_kgm3_oat_k"]
    odd = ["renamed", "duplicate_column", "header_only", "five_rows", "constant_time",
           "reversed_time", "short_rows", "long_rows", "semicolons"]
    broken = ["trunc_header", "utf16", "nul", "random", "empty", "blank", "bin_as", "ulg_as"]
    for command, template in FLIGHT_READERS.items():
        for name in missing + broken + (odd if command == "identify" else []):
            # cells beyond the header's columns are not read (a trailing comma is common)
            cases.append(Case(f"{command} file {name}", _with(template, f"{{root}}/{name}.csv"),
                              codes=(0, 2) if name == "long_rows" else (2,)))
    return cases


def _log_cases():
    names = [f"{what}.{kind}" for kind in ("bin", "ulg")
             for what in ("trunc1", "trunc50", "random", "empty", "csv_as", "zeroed_head")]
    names += ["text.log", "empty.log", "ulg_as.bin", "bin_as.ulg", "flight.tlog", "nodp.tlog",
              "trunc.tlog"]
    # a log whose first bytes are zeroed is read from the next intact message on
    return [Case(f"{command} log {name}", _with(template, f"{{root}}/{name}"),
                 codes=(0, 2) if name.startswith("zeroed_head") else (2,))
            for command, template in LOG_READERS.items() for name in names]


RESULT_VARIANTS = ["empty", "blank", "obj", "list", "null", "num", "str", "nested_list",
                   "nested_obj", "truncated", "trailing", "single_quotes", "flight_csv", "utf16",
                   "binary", "k1_nan", "k1_inf", "k1_1e200", "k1_099", "k1_str", "k1_null",
                   "k1_list", "k1_bool", "no_parameters", "no_k1", "params_list", "noise_zero",
                   "noise_neg", "model_unknown", "nm_rel_std_nan", "nm_rel_std_neg",
                   "nm_std_mps_nan", "nm_std_mps_neg", "nm_ar1_nan", "nm_ar1_neg",
                   "nm_block_s_nan", "nm_block_s_neg", "table_vi_neg", "table_vi_str",
                   "table_dv_nan", "table_not_list", "table_rows_str", "outer_list"]


def _result_cases():
    return [Case(f"{command} result {name}", _with(template, f"{{root}}/res_{name}.json"),
                 codes=(2,))
            for command, template in RESULT_READERS.items() for name in RESULT_VARIANTS]


def _aircraft_cases():
    report = ["report", "{result}", "-o", "{out}/r.html", "--aircraft"]
    names = ["ac_syntax.toml", "ac_empty_key.toml", "ac_deep.toml", "ac_typo.toml",
             "ac_bad_type.toml", "ac_nan_value.toml", "ac_table.toml", "ac_utf16.toml",
             "binary.toml", "folder", "nowhere.toml", "flight.csv", "result.json",
             "ac_weight_list.toml", "ac_type_nan.toml", "ac_misspelt.toml", "ac_date_table.toml",
             "ac_weight_negative.toml", "ac_speed_negative.toml"]
    # a top-level key outside the [aircraft]/[test] tables (`aircraft = 3`), and an unknown
    # key of an unknown table, are shown as given (the report's semantics)
    shown = ("ac_bad_type.toml", "ac_table.toml")
    return [Case(f"report aircraft {n}", report + [f"{{root}}/{n}"], words=("--aircraft",),
                 codes=(0, 2) if n in shown else (2,))
            for n in names]


def _legs_cases():
    names = ["nan", "text", "inf", "1e200", "kelvin", "ias_mps", "gs_mps", "track_rad", "alt_m",
             "two_legs", "empty_point", "negative_ias", "no_track", "header_only"]
    # altitudes in metres under pressure_alt_ft are plausible feet: read as feet
    return [Case(f"legs csv {n}", ["legs", f"{{root}}/legs_{n}.csv"],
                 codes=(0, 2, 3) if n == "alt_m" else (2, 3))
            for n in names]


# Every input of every command, given a folder, a missing file, a dangling link, a path
# through a file and a folder named like the file.
INPUTS = {"identify": (["identify", "{src}"], ".csv"),
          "legs": (["legs", "{src}"], ".csv"),
          "monitor": (["monitor", "{src}", "--calibration", "{result}"], ".csv"),
          "monitor-calibration": (["monitor", "{flight}", "--calibration", "{src}"], ".json"),
          "report": (["report", "{src}", "-o", "{out}/r.html"], ".json"),
          "report-flight": (["report", "{result}", "-o", "{out}/r.html", "--flight", "{src}"],
                            ".csv"),
          "plan-calibration": (["plan", "--calibration", "{src}", "-o", "{out}/p.csv"], ".json"),
          "simulate": (["simulate", "{src}", "-o", "{out}/f.csv"], ".csv"),
          "convert": (["convert", "{src}", "-o", "{out}/f.csv"], ".bin"),
          "legs-windows": (["legs", "{flight}", "--windows", "{src}"], ".csv")}


def _path_cases():
    cases = []
    for name, (template, ext) in INPUTS.items():
        ext_name = {".csv": "csv", ".json": "json", ".bin": "csv"}[ext]
        for what, src in (("folder", "{root}/folder"),
                          ("folder-ext", f"{{root}}/folder.{ext_name}"),
                          ("missing", f"{{root}}/nowhere{ext}"),
                          ("dangling", f"{{root}}/dangling.{ext_name}"),
                          ("through-file", f"{{flight}}/x{ext}")):
            cases.append(Case(f"{name} input {what}", _with(template, src)))
        # a file that opens but cannot be read (EIO): the unreadable file root can have
        cases.append(Case(f"{name} input unreadable", _with(template, "/proc/self/mem"),
                          words=("/proc/self/mem",), skip="" if os.path.exists("/proc/self/mem")
                          else "no /proc here"))
    return cases


# Every output flag, given the input itself, a link to it, a folder, a missing folder, "-"
# and an existing FIFO.
OUTPUTS = {"identify --json": (["identify", "{flight}", "--no-budget", "--json"], "{flight}"),
           "identify --plot": (["identify", "{flight}", "--no-budget", "--plot"], "{flight}"),
           "simulate -o": (["simulate", "{plan}", "-o"], "{plan}"),
           "convert -o": (["convert", "{bin}", "-o"], "{bin}"),
           "report -o": (["report", "{result}", "-o"], "{result}"),
           "legs --json": (["legs", "{flight}", "--json"], "{flight}"),
           "monitor --json": (["monitor", "{flight}", "--calibration", "{result}", "--json"],
                              "{result}"),
           "plan -o": (["plan", "--calibration", "{result}", "--no-figures", "-o"], "{result}")}


def _output_cases():
    cases = []
    for name, (template, target) in OUTPUTS.items():
        for what in ("same", "symlink", "hardlink", "folder", "no-folder", "dash", "fifo"):
            out = {"same": target, "symlink": "{out}/link.png", "hardlink": "{out}/hard.png",
                   "folder": "{out}", "no-folder": "{out}/nowhere/x.out", "dash": "-",
                   "fifo": "{out}/pipe"}[what]
            cases.append(Case(f"{name} output {what}", template + [out],
                              extra={"link": (what, target)}))
    return cases


PLAN_VARIANTS = ["wind_speed_mps_nan", "wind_speed_mps_1e9", "wind_speed_mps_abc",
                 "wind_speed_mps_-5", "wind_from_deg_nan", "wind_from_deg_[1,", "cell_nan",
                 "cell_text", "cas_zero", "reversed", "header_only", "one_row", "no_columns",
                 "short_row"]


def _plan_cases():
    """A plan CSV with a bad comment value or body: named by its file and line or column,
    never as a flag the user did not give."""
    cases = []
    for name in PLAN_VARIANTS:
        words = ("comment line",) if name.startswith("wind") else ("plan_",)
        cases.append(Case(f"simulate plan {name}", ["simulate", f"{{root}}/plan_{name}.csv",
                                                    "-o", "{out}/f.csv"], words=words))
    for what in ("flight.csv", "result.json", "flight.bin", "legs.csv", "utf16.csv",
                 "empty.csv"):
        cases.append(Case(f"simulate plan {what}", ["simulate", f"{{root}}/{what}", "-o",
                                                    "{out}/f.csv"]))
    return cases


def _stream_cases():
    with_log = {"identify": ["identify", "-", "--no-budget"], "legs": ["legs", "-"],
                "monitor": ["monitor", "-", "--calibration", "{result}"]}
    data = {"empty": b"", "garbage": b"1,2,3\n4,5,6\n", "binary": bytes(range(256)) * 8,
            "utf16": "time_s,qc_pa\n1,2\n".encode("utf-16")}
    cases = [Case(f"{c} stdin {n}", argv, stdin=d)
             for c, argv in with_log.items() for n, d in data.items()]
    cases += [Case(f"identify fifo {n}", ["identify", "{out}/in.fifo", "--no-budget"],
                   fifo=n) for n in data]
    # autopilot logs on a pipe or a FIFO: read once, as from their file
    logs = {"identify": ["identify", "{src}", "--no-budget"],
            "convert": ["convert", "{src}", "-o", "{out}/c.csv"], "legs": ["legs", "{src}"]}
    for command, template in logs.items():
        for log, ok in (("log_bin", True), ("log_ulg", True), ("trunc50.bin", False),
                        ("random.ulg", False)):
            codes = (0, 2) if ok and command == "legs" else (0,) if ok else (2,)
            cases.append(Case(f"{command} stdin {log}", _with(template, "-"), codes=codes,
                              extra={"stdin_file": log}))
        cases.append(Case(f"{command} fifo log_bin", _with(template, "{out}/in.bin"),
                          fifo="log_bin", codes=(0, 2) if command == "legs" else (0,)))
    cases += [Case("report stdin garbage", ["report", "-", "-o", "{out}/r.html"],
                   stdin=b"{not json"),
              Case("monitor calibration stdin", ["monitor", "{flight}", "--calibration", "-"],
                   stdin=b"[[[["),
              Case("simulate plan stdin garbage", ["simulate", "-", "-o", "{out}/f.csv"],
                   stdin=b"t_s,x\n1,2\n"),
              Case("convert stdin garbage", ["convert", "-", "-o", "{out}/f.csv"],
                   stdin=b"garbage")]
    return cases


def _option_cases():
    """Integer and choice options given a value that is none (float options: the numeric-option
    test), and a few option combinations that mean nothing."""
    parser = build_parser()
    base = {"demo": ["demo", "--out", "{out}/demo"], "plan": ["plan", "-o", "{out}/p.csv"],
            "simulate": ["simulate", "{plan}", "-o", "{out}/f.csv"],
            "identify": ["identify", "{flight}"], "convert": ["convert", "{bin}", "-o",
                                                              "{out}/c.csv"],
            "legs": ["legs", "{flight}"], "report": ["report", "{result}", "-o", "{out}/r.html"],
            "monitor": ["monitor", "{flight}", "--calibration", "{result}"],
            "study": ["study", "budget", "--out", "{out}"]}
    cases = []
    for name, sub in parser._subparsers._group_actions[0].choices.items():
        for action in sub._actions:
            if not action.option_strings or action.nargs == 0:
                continue
            flag = max(action.option_strings, key=len)
            if action.type is int:
                values = ("abc", "1.5", "-1")
            elif action.choices is not None:
                values = ("xyz", "")
            else:
                continue
            for value in values:
                cases.append(Case(f"{name} {flag} {value!r}", base[name] + [flag, value],
                                  words=(flag,)))
    cases += [Case("plan --center 91 0", base["plan"] + ["--center", "91", "0"]),
              Case("plan --center 0 181", base["plan"] + ["--center", "0", "181"]),
              Case("plan --center 90 0 --export", base["plan"] + ["--center", "90", "0",
                                                                  "--export", "ardupilot"]),
              Case("plan --center 89.9 0 --export", base["plan"] + ["--center", "89.9", "0",
                                                                    "--export", "px4"],
                   words=("--center 89.9 0", "pole")),
              Case("plan --center -90 0", base["plan"] + ["--center", "-90", "0"],
                   words=("--center -90 0",)),
              Case("plan --duration-s 1", base["plan"] + ["--duration-s", "1"],
                   words=("--duration-s 1",)),
              Case("identify --start-s > --end-s", base["identify"] + ["--start-s", "50",
                                                                         "--end-s", "10"]),
              Case("identify window past the end", base["identify"] + ["--start-s", "1e5"]),
              Case("identify --live and a file", base["identify"] + ["--live",
                                                                     "udp:127.0.0.1:14550"]),
              *[Case(f"identify --columns {n}", base["identify"] + ["--columns", f"{{root}}/{n}"],
                     words=("--columns /",))
                for n in ("binary.toml", "ac_syntax.toml", "ac_deep.toml", "folder",
                          "nowhere.toml", "flight.csv", "ac_utf16.toml", "ac_typo.toml")],
              Case("simulate --fault garbage", base["simulate"] + ["--fault", "leak"]),
              Case("simulate --fault onset past", base["simulate"] + ["--fault",
                                                                      "blocked:1e9:30"]),
              Case("simulate --aircraft missing", base["simulate"] + ["--engine", "jsbsim",
                                                                      "--aircraft", "nowhere"]),
              Case("legs --windows garbage", base["legs"] + ["--windows", "a-b,c"]),
              Case("legs --windows reversed", base["legs"] + ["--windows", "50-10"]),
              Case("monitor udp port 0", ["monitor", "udp:127.0.0.1:0", "--calibration",
                                          "{result}"]),
              Case("report --speed-range-kt reversed", base["report"] + ["--speed-range-kt",
                                                                         "120", "60"]),
              Case("study unknown", ["study", "nothing"]),
              Case("study --out a file", ["study", "budget", "--quick", "--out", "{flight}"],
                   words=("--out",)),
              Case("demo --out a file", ["demo", "--out", "{flight}"], words=("--out",)),
              Case("demo --out through a file", ["demo", "--out", "{flight}/demo"]),
              Case("study real-alfa --data empty", ["study", "real-alfa", "--data",
                                                    "{root}/folder", "--out", "{out}"],
                   words=("--data",)),
              Case("study real-alfa --data missing", ["study", "real-alfa", "--data",
                                                      "{root}/nowhere", "--out", "{out}"],
                   words=("--data",)),
              Case("study real-alfa --data garbage", ["study", "real-alfa", "--data",
                                                      "{root}/alfa", "--out", "{out}"],
                   words=("scaled_pressure.csv",)),
              Case("study --run-index past the grid", ["study", "budget", "--quick",
                                                       "--run-index", "100000", "--out",
                                                       "{out}"]),
              Case("no command", []),
              Case("unknown command", ["calibrate"])]
    return cases


CASES = (_flight_cases() + _log_cases() + _result_cases() + _aircraft_cases() + _legs_cases()
         + _plan_cases() + _path_cases() + _output_cases() + _stream_cases() + _option_cases())


# --- the runner ------------------------------------------------------------------------------

class _Hang(Exception):
    pass


def _on_alarm(signum, frame):
    raise _Hang


def _fill(text, files, out):
    names = {"root": files["root"], "out": out, "flight": files["flight"],
             "result": files["result"], "plan": files["plan"], "bin": files["log_bin"]}
    for key, value in names.items():
        text = text.replace("{" + key + "}", str(value))
    return text


def _prepare(case, files, out):
    """Links, FIFOs and stdin of `case`; returns a clean-up function."""
    what, target = case.extra.get("link", (None, None))
    target = _fill(target, files, out) if target else None
    if what == "symlink":
        os.symlink(target, out / "link.png")
    elif what == "hardlink":
        os.link(target, out / "hard.png")
    elif what == "fifo":
        os.mkfifo(out / "pipe")
    cleanups = []
    if case.fifo is not None:
        fifo = out / ("in.bin" if case.fifo.startswith("log_") else "in.fifo")
        os.mkfifo(fifo)
        payload = (files[case.fifo].read_bytes() if case.fifo.startswith("log_")
                   else _stream_data()[case.fifo])

        def feed():
            try:
                with open(fifo, "wb") as f:
                    f.write(payload)
            except OSError:
                pass

        thread = threading.Thread(target=feed, daemon=True)
        thread.start()

        def release():          # the writer is blocked if nobody opened the FIFO
            fd = os.open(fifo, os.O_RDONLY | os.O_NONBLOCK)
            thread.join(timeout=2)
            os.close(fd)
        cleanups.append(release)
    return cleanups


def _stream_data():
    return {"empty": b"", "garbage": b"1,2,3\n4,5,6\n", "binary": bytes(range(256)) * 8,
            "utf16": "time_s,qc_pa\n1,2\n".encode("utf-16")}


class _Stdin:
    def __init__(self, data):
        import io
        self.buffer = io.BytesIO(data)

    def read(self, *args):
        return self.buffer.read(*args).decode("utf-8", "replace")


def run_case(case, files, out, capsys, monkeypatch):
    """(exit status, stderr, problem or None) of one case."""
    argv = [_fill(a, files, out) for a in case.argv]
    if "stdin_file" in case.extra:
        name = case.extra["stdin_file"]
        data = (files[name] if name in files else files["root"] / name).read_bytes()
        monkeypatch.setattr(sys, "stdin", _Stdin(data))
    elif case.stdin is not None:
        monkeypatch.setattr(sys, "stdin", _Stdin(case.stdin))
    cleanups = _prepare(case, files, out)
    inputs = [Path(a) for a in argv if a.startswith(str(files["root"]))]
    before = {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in inputs
              if p.is_file() and not p.is_symlink()}
    listing = sorted(os.listdir(files["root"]))
    sigint = signal.getsignal(signal.SIGINT)
    previous = signal.signal(signal.SIGALRM, _on_alarm)
    signal.alarm(LIMIT_S)
    problem = None
    try:
        with warnings.catch_warnings():
            warnings.simplefilter("default")
            try:
                code = main(argv)
            except SystemExit as stop:
                code = stop.code
    except _Hang:
        code, problem = None, f"no answer within {LIMIT_S} s"
    except Exception as exc:  # noqa: BLE001 - a traceback is what this suite looks for
        code, problem = None, f"traceback: {type(exc).__name__}: {exc}"[:300]
    finally:
        signal.alarm(0)
        signal.signal(signal.SIGALRM, previous)
        for clean in cleanups:
            clean()
    err = capsys.readouterr().err
    code = 0 if code is None and problem is None else code
    if problem is None and signal.getsignal(signal.SIGINT) is not sigint:
        problem = f"the Ctrl-C handler was left changed: {signal.getsignal(signal.SIGINT)}"
        signal.signal(signal.SIGINT, sigint)
    if problem is None:
        after = {p: hashlib.sha256(p.read_bytes()).hexdigest() for p in before}
        if after != before or sorted(os.listdir(files["root"])) != listing:
            problem = "an input file or folder changed"
    return code, err, problem


def _judge(case, code, err, problem):
    if problem:
        return problem
    if "Traceback" in err:
        return "traceback on stderr"
    if code not in case.codes:
        return f"exit {code}, expected {case.codes}"
    if code not in (0, 1):
        # warnings (about what was read before the refusal) may precede the one error line
        lines = [line for line in err.splitlines() if not line.startswith("warning:")]
        if len(lines) != 1 or not lines[0].startswith("pitotcal"):
            return f"{len(lines)} error lines, expected one 'pitotcal ...' line"
        missing = [w for w in case.words if w not in lines[0]]
        if missing:
            return f"the message does not name {missing}"
    return None


@pytest.mark.parametrize("case", CASES, ids=[c.id for c in CASES])
def test_bad_input(case, files, tmp_path, capsys, monkeypatch):
    if case.skip:
        pytest.skip(case.skip)
    monkeypatch.chdir(tmp_path)         # a stray relative output lands here, not in the tree
    code, err, problem = run_case(case, files, tmp_path, capsys, monkeypatch)
    verdict = _judge(case, code, err, problem)
    assert verdict is None, f"pitotcal {' '.join(case.argv)}: {verdict}\n{err.strip()[-600:]}"


def test_the_suite_counts_at_least_300_cases(capsys):
    ids = [c.id for c in CASES]
    assert len(set(ids)) == len(ids), "case ids repeat"
    with capsys.disabled():
        print(f"\nbad-input suite: {len(CASES)} cases")
    assert len(CASES) >= MIN_CASES


def test_no_input_file_changed_during_the_suite(files):
    assert _checksums(files["root"]) == files["sums"]
