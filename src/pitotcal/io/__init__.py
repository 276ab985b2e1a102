"""Reading and writing pitotcal's files: flight CSV, autopilot logs, plan CSV, result records.

`read_flight(path)` is the one entry point for flight data: `.ulg` (PX4 ULog), `.bin` / `.log`
(ArduPilot DataFlash) go to `pitotcal.io.logs.read_log`; anything else is read as a flight CSV
by `pitotcal.io.flight_csv.read_flight_csv`.
"""

from pathlib import Path

import dataclasses

from pitotcal.core.errors import PitotcalError
from pitotcal.core.flight import Flight
from pitotcal.core.moist_air import check_air_options, with_static_air

from .flight_checks import check_window
from .flight_csv import read_flight_csv, write_flight_csv
from .plan_csv import read_plan, write_plan
from .read_once import log_suffix, naming, read_once
from .result_record import read_result
from .streams import LOG_EXTENSIONS

__all__ = [
    "LOG_EXTENSIONS",
    "Flight",
    "is_log_file",
    "read_flight",
    "read_flight_csv",
    "read_plan",
    "read_result",
    "with_reading",
    "write_flight_csv",
    "write_plan",
]


def is_log_file(path):
    """Whether `read_flight` reads `path` as an autopilot log (by its extension), not a CSV."""
    return Path(path).suffix.lower() in LOG_EXTENSIONS


def read_flight(path, start_s=None, end_s=None, *, oat_k=None, temp_recovery=1.0, rh_pct=None,
                columns=None, oat_ground_k=None, windows="all"):
    """Read a calibration flight from a flight CSV or an autopilot log.

    Parameters
    ----------
    path : str or path-like
        A flight CSV (docs/interfaces.md §1) or a log: `.ulg` (PX4 ULog), `.bin`/`.log` (ArduPilot
        DataFlash), read by `pitotcal.io.logs.read_log`; ``-`` (standard input) or a FIFO is
        read once, whole (`pitotcal.io.read_once`), a log on it known by its first bytes.
    start_s, end_s : float, optional
        Keep only samples with start_s <= time_s <= end_s, s (e.g. cut off taxi and take-off).
        Validation (the 1 % bad-row rule) applies inside this window only.
    oat_k : float, optional
        Logs only: a measured outside air temperature, K, for the density (see `load_log`).
    oat_ground_k : float, optional
        Logs only: the ground temperature at the take-off point, K, carried up the standard
        lapse (`pitotcal.io.oat`).
    windows : {"all", "auto"}
        Logs only: keep every usable sample (default), or, without `start_s`/`end_s`, choose
        the calibration windows from the log (`pitotcal.io.windows`).
    temp_recovery : float
        Recovery factor of the total-temperature probe of a `tat_k` column, 0-1:
        T_s = T_t / (1 + r 0.2 M²) (`pitotcal.core.moist_air.with_static_air`).
    rh_pct : float, optional
        Relative humidity, %, overriding an `rh_pct` column (default: the column, else dry).
    columns : str or path-like, optional
        A column mapping (TOML, docs/interfaces.md §1b): `path` is then any CSV export whose
        columns and units the mapping names (`pitotcal.io.mapped_csv.read_mapped_csv`).

    Returns
    -------
    Flight
        With its air data made once, here: `oat_k` the static (virtual, when humid)
        temperature and `rho_kgm3` from it; `Flight.reading` records how (start_s, end_s,
        oat_k, temp_recovery, rh_pct, oat_source), and `identify` puts it in the result
        record. `Flight.warnings` holds every warning the reader gave (also issued with
        `warnings.warn`): dropped rows, sensor temperature used as OAT, corrupt data skipped.

    Raises
    ------
    FlightDataError
        Unusable data; the one-line message names file, column and row (module docstring).
        A plan CSV is refused as a plan to fly or simulate first.
    PitotcalError
        A bad window or `oat_k` (its `param` names the parameter).
    OSError
        The file cannot be opened.

    Examples
    --------
    >>> flight = read_flight("flight.csv", start_s=60.0)            # doctest: +SKIP
    >>> flight.n, flight.meta.get("aircraft")                        # doctest: +SKIP
    (16000, 'T-2')
    """
    start_s, end_s = check_window(start_s, end_s)
    temp_recovery, rh_pct = check_air_options(temp_recovery, rh_pct)
    reading = {"start_s": start_s, "end_s": end_s, "oat_k": oat_k,
               "temp_recovery": temp_recovery, "rh_pct": rh_pct}
    log_options = {"oat_ground_k": oat_ground_k, "windows": windows}
    if oat_ground_k is not None:
        reading["oat_ground_k"] = oat_ground_k
    if columns is not None:
        if is_log_file(path) or oat_k is not None or oat_ground_k is not None:
            raise PitotcalError(f"columns applies to CSV exports only, without oat_k; "
                                f"{Path(path).name} is read as it is", param="columns")
        from .mapped_csv import read_mapped_csv
        return with_reading(read_mapped_csv(path, columns, start_s, end_s,
                                            temp_recovery=temp_recovery, rh_pct=rh_pct),
                            {**reading, "columns": str(columns)})
    with naming(path):
        return _read_flight(read_once(path), reading, log_options)


def _read_flight(path, reading, log_options):
    """`read_flight` of `path` (a file, or a stream's bytes read once) with `reading` checked."""
    start_s, end_s, oat_k = reading["start_s"], reading["end_s"], reading["oat_k"]
    temp_recovery, rh_pct = reading["temp_recovery"], reading["rh_pct"]
    if is_log_file(path) or log_suffix(path):       # a log by its name, or on a stream by its bytes
        from .logs import read_log
        flight = read_log(path, start_s=start_s, end_s=end_s, oat_k=oat_k, **log_options)
        return with_reading(with_static_air(flight, temp_recovery=temp_recovery,
                                            rh_pct=rh_pct), reading)
    if log_options["oat_ground_k"] is not None:
        raise PitotcalError(f"oat_ground_k applies to {'/'.join(LOG_EXTENSIONS)} logs only; "
                            f"{Path(path).name} is a flight CSV", param="oat_ground_k")
    if oat_k is not None:
        raise PitotcalError(f"oat_k applies to {'/'.join(LOG_EXTENSIONS)} logs only; "
                            f"{Path(path).name} is a flight CSV, whose density comes from its "
                            "rho_kgm3 or ps_pa/oat_k columns", param="oat_k")
    return with_reading(read_flight_csv(path, start_s=start_s, end_s=end_s,
                                        temp_recovery=temp_recovery, rh_pct=rh_pct), reading)


def with_reading(flight, reading):
    """`flight` with `reading` (start_s, end_s, oat_k, temp_recovery, rh_pct) recorded in
    `Flight.reading`, and `oat_source`, where its temperature came from, added."""
    meta = flight.meta
    if meta.get("temperature_source"):
        source = str(meta["temperature_source"])
    elif meta.get("oat_k_source"):
        source = str(meta["oat_k_source"])
    elif flight.oat_k is not None:
        source = "oat_k"
    else:
        source = None                   # the density is the file's rho_kgm3
    # the reader's own record (a log's chosen windows and cuts) stays
    return dataclasses.replace(flight, reading={**(flight.reading or {}), **reading,
                                                "oat_source": source})
