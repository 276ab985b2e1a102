"""The calibration report: one self-contained HTML file from a result JSON.

`build_report` gathers what the template shows (title block, test conditions, method, the
correction tables, figures as base64 PNG, warnings, compliance, legs, provenance, signatures);
`render_html` fills the jinja2 template `templates/report.html.j2` (package data). Missing
additions of newer results are said, not hidden: without `dv_U_kt` the tables and the verdict
say that only the statistical 2σ is included; without `dh_ft` the altimeter check is not
demonstrated.
"""

import base64
import datetime
import hashlib
import math
import warnings
from pathlib import Path

import numpy as np

from pitotcal.core.errors import PitotcalError
from pitotcal.io.atomic import atomic_open, atomic_path

from . import compliance as comp
from .aircraft_file import AIRCRAFT_FIELDS, aircraft_rule, read_aircraft
from .budget_tables import budget_report
from .conditions import turbulence_text
from .refit import refit, reproduces

__all__ = ["AIRCRAFT_FIELDS", "build_report", "make_report", "read_aircraft", "read_result",
           "render_html", "sha256", "write_pdf"]

def sha256(path):
    """SHA-256 hex digest of a file."""
    h = hashlib.sha256()
    with open(path, "rb") as f:
        for block in iter(lambda: f.read(1 << 20), b""):
            h.update(block)
    return h.hexdigest()


def _png(data):
    return None if data is None else base64.b64encode(data).decode("ascii")


def _fmt(x, spec):
    return "—" if x is None or (isinstance(x, float) and not math.isfinite(x)) else format(x, spec)


def build_report(result, *, flight=None, aircraft_rows=(), regulation="23.1323",
                 speed_range_kt=None, inputs=(), options=None, ident=None,
                 configuration=None, speeds_kcas=None):
    """Everything the report template shows, as a plain dict.

    Parameters
    ----------
    result : dict
        The result JSON (docs/interfaces.md §3, with the §9 additions when present).
    flight : Flight, optional
        The flight the result came from: test conditions, and with `ident` the figures of the fit.
    aircraft_rows : sequence of (label, text)
        The title block (`read_aircraft`).
    regulation, speed_range_kt, configuration, speeds_kcas
        Passed to `compliance.assess`.
    inputs : sequence of (role, path)
        Files whose SHA-256 the provenance lists.
    options : dict, optional
        Every option the report was made with (provenance).
    ident : IdentificationResult, optional
        The fit re-run on `flight` for the figures that need samples.

    Returns
    -------
    dict
        Keys of the template (module docstring) plus ``compliance`` (the JSON block).
    """
    from pitotcal import __version__

    from . import figures as figs

    block = comp.assess(result, regulation, speed_range_kt, configuration=configuration,
                        speeds_kcas=speeds_kcas)
    rows = result.get("airspeed_correction") or []
    has_u = bool(rows) and all(r.get("dv_U_kt") is not None for r in rows)
    warnings = list(result.get("warnings", []))
    if not result.get("converged", True):
        warnings.insert(0, "the solver did not converge: the numbers are not a calibration")
    if not has_u:
        warnings.append("the result has no expanded uncertainty U (dv_U_kt): tables and "
                        "verdict include only the statistical 2σ")
    figures = [("Airspeed correction", _png(figs.correction_png(result, block)))]
    alt = figs.altimeter_png(result, block)
    if alt is not None:
        figures.append(("Altimeter correction", _png(alt)))
    if ident is not None and flight is not None:
        if "points" not in result:      # a legs result is another method: not comparable
            warnings += reproduces(result, ident)
        figures.append(("Calibration (paper Figs. 7-8 style), with the residual time history",
                        _png(figs.calibration_png(ident, result))))
        figures.append(("Ground track and residual distribution", _png(figs.track_png(flight,
                                                                                      ident))))
    now = datetime.datetime.now(datetime.UTC).strftime("%Y-%m-%d %H:%M:%S UTC")
    return {
        "title_rows": list(aircraft_rows),
        "conditions": _conditions(result, flight),
        "method": _method(result),
        "correction_rows": [_correction_row(r) for r in rows],
        "has_u": has_u,
        "budget": budget_report(result),
        "altimeter_rows": [r for r in rows if r.get("dh_ft") is not None],
        "mach_rows": _mach_rows(result),
        "figures": figures,
        "warnings": warnings,
        "compliance": block,
        "legs": _legs(result),
        "provenance": {"version": __version__, "date": now, "options": _option_rows(options),
                       "inputs": [(role, str(p), sha256(p)) for role, p in inputs]},
        "fmt": _fmt,
    }


def _param(result, name, scale=1.0):
    entry = (result.get("parameters") or {}).get(name) or {}
    value, std = entry.get("value"), entry.get("std")
    return (None if value is None else value * scale,
            None if std is None else 2 * std * scale)


def _conditions(result, flight):
    """(label, text) rows: wind with 2σ, turbulence indication, samples, altitude, time."""
    from pitotcal.core.units import m_to_ft, mps_to_kt

    spd, spd2 = _param(result, "wind_speed_mps", mps_to_kt(1.0))
    frm, frm2 = _param(result, "wind_from_deg")
    rows = [("Wind (identified)", (f"{_fmt(spd, '.1f')} ± {_fmt(spd2, '.1f')} kt from "
                                  f"{_fmt(frm, '.0f')}° ± {_fmt(frm2, '.1f')}° true (2σ)")),
            ("Samples used", (f"{result.get('n_samples', '—')} "
                             f"({result.get('n_dropped', 0)} dropped by the reader)")),
            ("Residual RMS", f"{_fmt(result.get('noise_std_pa'), '.2f')} Pa"),
            ("Turbulence indication", turbulence_text(result))]
    if flight is not None:
        t = flight.time_s
        rows.append(("Flight time", f"{t[-1] - t[0]:.0f} s ({t[0]:.1f}–{t[-1]:.1f} s)"))
        if flight.alt_m is not None and (alt := flight.alt_m[np.isfinite(flight.alt_m)]).size:
            lo, hi = f"{m_to_ft(alt.min()):.0f}", f"{m_to_ft(alt.max()):.0f}"
            rows.append(("Altitude (GPS)", f"{lo} ft" if lo == hi else f"{lo}–{hi} ft"))
        lo, hi = f"{flight.rho_kgm3.min():.4f}", f"{flight.rho_kgm3.max():.4f}"
        rows.append(("Air density", f"{lo} kg/m³" if lo == hi else f"{lo}–{hi} kg/m³"))
        for key in ("oat_source", "temperature_source", "autopilot", "firmware"):
            if key in flight.meta:
                rows.append((key.replace("_", " ").capitalize(), str(flight.meta[key])))
    oat = (result.get("reading") or {}).get("oat_source")
    if oat and (flight is None or "temperature_source" not in flight.meta):
        rows.append(("Temperature source", str(oat)))
    if result.get("windows"):
        from pitotcal.io.windows import windows_text

        lines = windows_text(result).splitlines()
        rows.append(("Calibration windows", "; ".join(line for line in lines
                                                      if not line.startswith("cut: "))))
        rows += [("Cut from the log", line[5:]) for line in lines if line.startswith("cut: ")]
    if result.get("source"):
        rows.append(("Result source", str(result["source"])))
    return rows


def _method(result):
    params = result.get("parameters") or {}
    coefs = ", ".join(f"{n} = {p['value']:.5g} ± {2 * p['std']:.2g}" for n, p in params.items()
                      if isinstance(p, dict) and not n.startswith("wind")
                      and p.get("value") is not None and p.get("std") is not None)
    air = result.get("air_data")
    return [
        ("Method", ("global output-error identification from GPS (NASA AirSTAR); pressure "
                   "error and wind estimated together, the track turning through the wind")),
        ("Pressure-error model", f"{result.get('model', '—')}: {result.get('formula', '')}"),
        ("Coefficients (2σ)", coefs or "—"),
        ("Air data", air if air else "incompressible (the result records no air-data mode)"),
        ("Static vs total error", ("the method measures the total pressure error Δp_p of the "
                                  "pitot-static pair and does not separate static-source from "
                                  "total-pressure error; ΔH_pc is shown only when the result "
                                  "carries it (dh_ft), under the result's own assumption")),
        ("Uncertainty", "2σ: statistical, corrected for coloured residuals; U: expanded "
                        "uncertainty (k = 2) of the result's uncertainty budget"
                        if result.get("uncertainty_budget") else
                        "2σ: statistical, corrected for coloured residuals (no budget in the "
                        "result: systematic contributions not included)"),
    ]


def _option_rows(options):
    """(name, text) of the options given, as a person reads them: unset ones (None, False,
    empty) left out, True as "yes", sequences space-separated, numbers in %g."""
    def text(v):
        if isinstance(v, (list, tuple)):
            return " ".join(text(x) for x in v)
        return "yes" if v is True else format(v, "g") if isinstance(v, float) else str(v)

    return [(k.replace("_", " "), text(v)) for k, v in sorted((options or {}).items())
            if v is not None and v is not False and v not in ((), [], "")]


def _correction_row(r):
    return {"vi": r.get("vi_kt"), "dv": r.get("dv_kt"), "two": r.get("dv_2sigma_kt"),
            "u": r.get("dv_U_kt"), "vc": r.get("vc_kt")}


def _mach_rows(result):
    """Δp_p/q_cic vs M_ic from each row's V_i and V_c, when the result has mach_i."""
    rows = [r for r in result.get("airspeed_correction") or [] if r.get("mach_i") is not None]
    if not rows:
        return []
    from pitotcal.core.airdata import airspeed_law
    from pitotcal.core.units import kt_to_mps

    qc_from_cas_pa = airspeed_law(result.get("air_data") or "incompressible")[0]

    out = []
    for r in rows:
        ratio = r.get("dpp_qcic")       # the identification's own Δp_p/q_cic, when it gave it
        if ratio is None:
            qci = float(qc_from_cas_pa(kt_to_mps(r["vi_kt"])))
            ratio = (float(qc_from_cas_pa(kt_to_mps(r["vc_kt"]))) - qci) / qci
        out.append({"mach": r["mach_i"], "dmach": r.get("dmach"), "ratio": ratio,
                    "vi": r["vi_kt"]})
    return out


def _legs(result):
    points = result.get("points")
    if not isinstance(points, list) or not points:
        return None
    keys = [k for k in ("point", "ias_kt", "tas_kt", "tas_2sigma_kt", "wind_speed_kt",
                        "wind_from_deg", "dv_kt", "dv_2sigma_kt", "method")
            if any(k in p for p in points)]
    glob = result.get("global")
    return {"keys": keys, "points": points,
            "global": sorted(glob.items()) if isinstance(glob, dict) else []}


def render_html(context):
    """The report as one HTML string (jinja2, autoescaped; template from the package)."""
    import jinja2

    env = jinja2.Environment(
        loader=jinja2.PackageLoader("pitotcal.estimation.reporting", "templates"),
        autoescape=True, undefined=jinja2.StrictUndefined, trim_blocks=True,
        lstrip_blocks=True)
    return env.get_template("report.html.j2").render(**context)


def write_pdf(html_path, pdf_path):
    """Print the HTML report to PDF with headless Chromium (``--print-to-pdf``).

    Raises
    ------
    PitotcalError
        No Chromium on PATH, or it failed.
    """
    import shutil
    import subprocess

    browser = next((shutil.which(b) for b in ("chromium", "chromium-browser", "google-chrome")
                    if shutil.which(b)), None)
    if browser is None:
        raise PitotcalError("`pdf_path` needs Chromium on PATH (Debian: apt-get install chromium)")
    # printed to a temporary file beside it, renamed when whole (pitotcal.io.atomic)
    with atomic_path(pdf_path) as tmp:
        cmd = [browser, "--headless", "--no-sandbox", "--disable-gpu", "--no-pdf-header-footer",
               f"--print-to-pdf={Path(tmp).resolve()}", Path(html_path).resolve().as_uri()]
        proc = subprocess.run(cmd, capture_output=True, text=True, timeout=120, check=False)
        if proc.returncode != 0 or not Path(tmp).stat().st_size:
            raise PitotcalError(f"`pdf_path`: Chromium failed ({proc.stderr.strip()[-200:]})")
    return pdf_path


def read_result(path):
    """The report's input as a dict: a result record, validated by the library's one reader
    (`pitotcal.io.result_record.read_result`), or a `pitotcal legs --json` as a result
    (`legs_as_result`: its global fit, with the legs table); a one-line PitotcalError naming
    the file (and the key) when it is neither."""
    from pitotcal.io.jsonfile import read_json
    from pitotcal.io.result_record import read_result as read_record

    from ..legs.report import legs_as_result

    doc = read_json(path)
    if isinstance(doc, dict) and not doc.get("airspeed_correction"):
        legs = legs_as_result(doc)
        if legs is not doc and legs.get("airspeed_correction"):
            return legs
    return read_record(doc, name=str(path))


# the reading a result records that `read_flight` takes (its "oat_source" is a description)

def make_report(result_path, html_path, *, flight_path=None, flight_options=None,
                aircraft_path=None,
                regulation="23.1323", speed_range_kt=None, json_path=None, pdf_path=None,
                options=None, configuration=None):
    """Read the inputs, write the HTML report (and the JSON / PDF when asked).

    `flight_options` are the reading identify used: start_s, end_s, oat_k, temp_recovery,
    rh_pct (`pitotcal.io.read_flight`, which makes the air data); those not given (None) come
    from the result's `reading`. `configuration` (the configuration flown) overrides the
    aircraft file's; the file's stall speeds set the verdict's speed ranges (`aircraft_rule`).
    The re-fit takes the result's model, air-data mode (`air_data`; "incompressible" when it
    records none), GPS noise, stated GPS error (`gps_error`) and the probe lever arm identify
    corrected the data for (`reading.probe_arm_m`).

    Returns
    -------
    dict
        ``compliance`` (the JSON block) and ``written`` (the paths written, in order).
    """
    result = read_result(result_path)
    inputs = [("Result JSON", result_path)]
    flight = ident = None
    if flight_path is not None:
        flight, ident = refit(result, flight_path, flight_options)
        inputs.append(("Flight", flight_path))
    rows, rule = (), {"configuration": None, "speeds_kcas": {}}
    if aircraft_path is not None:
        rows = read_aircraft(aircraft_path)
        rule = aircraft_rule(aircraft_path)
        inputs.append(("Aircraft file", aircraft_path))
    context = build_report(result, flight=flight, aircraft_rows=rows, regulation=regulation,
                           speed_range_kt=speed_range_kt, inputs=inputs, options=options,
                           ident=ident, configuration=configuration or rule["configuration"],
                           speeds_kcas=rule["speeds_kcas"])
    html = render_html(context)
    with atomic_open(html_path, "w", encoding="utf-8") as fh:
        fh.write(html)
    written = [html_path]
    if json_path is not None:
        from pitotcal.io.jsonfile import write_json

        write_json(json_path, {**result, "warnings": context["warnings"],
                               "compliance": context["compliance"]})
        written.append(json_path)
    if pdf_path is not None:
        written.append(write_pdf(html_path, pdf_path))
    # the report's own warnings (the result's were said when it was made), after the files
    for message in context["warnings"]:
        if message not in result.get("warnings", []):
            warnings.warn(message, stacklevel=2)
    return {"compliance": context["compliance"], "written": written}
