"""A radiosonde sounding in the USAF range text format (an independent wind, temperature and
pressure by altitude), and its values at a test altitude.

The file starts with a few identification lines, then a two-line header whose first columns
are ``ALT DIR SPD SHR TEMP DPT PRESS`` with units ``GEOMFT DEG KTS /SEC DEG C DEG C MBS``
(geometric altitude ft, the direction the wind blows FROM deg true, speed kt, shear, temperature
°C, dew point °C, pressure mb), and one row per altitude until a line that is not numbers
(``TERMINATION``, or the mandatory-levels section, which is not read).
"""

import dataclasses

import numpy as np

from pitotcal.core.errors import FlightDataError
from pitotcal.core.units import FT_TO_M, KT_TO_MPS, PA_PER_UNIT, wind_vector_mps

__all__ = ["Sounding", "read_sounding"]

_HEADER = ("ALT", "DIR", "SPD", "SHR", "TEMP", "DPT", "PRESS")


@dataclasses.dataclass(frozen=True)
class Sounding:
    """A sounding in SI: `alt_m` geometric altitude, `wind_n_mps`/`wind_e_mps` the air mass's
    velocity (the way it blows TO), `temp_k`, `ps_pa`; `source` the file, `title` its first
    lines."""

    alt_m: np.ndarray
    wind_n_mps: np.ndarray
    wind_e_mps: np.ndarray
    temp_k: np.ndarray
    ps_pa: np.ndarray
    source: str
    title: str

    def at(self, alt_m):
        """{"wind_n_mps", "wind_e_mps", "temp_k", "ps_pa"} interpolated at `alt_m` (m);
        the pressure log-linearly."""
        alt_m = float(alt_m)
        if not self.alt_m[0] <= alt_m <= self.alt_m[-1]:
            raise FlightDataError(f"{self.source}: altitude {alt_m:.0f} m is outside the "
                                  f"sounding ({self.alt_m[0]:.0f}-{self.alt_m[-1]:.0f} m)")
        return {"wind_n_mps": float(np.interp(alt_m, self.alt_m, self.wind_n_mps)),
                "wind_e_mps": float(np.interp(alt_m, self.alt_m, self.wind_e_mps)),
                "temp_k": float(np.interp(alt_m, self.alt_m, self.temp_k)),
                "ps_pa": float(np.exp(np.interp(alt_m, self.alt_m, np.log(self.ps_pa))))}

    def wind_spread_mps(self, alt_m, half_layer_m):
        """The largest change of the wind vector from its value at `alt_m` over the sounding's
        levels within ±`half_layer_m` (m/s; 0 with none): how far the sounding itself moves
        within a layer of that depth, e.g. where a thin wind maximum lies."""
        here = self.at(alt_m)
        near = np.abs(self.alt_m - float(alt_m)) <= float(half_layer_m)
        if not np.any(near):
            return 0.0
        return float(np.max(np.hypot(self.wind_n_mps[near] - here["wind_n_mps"],
                                     self.wind_e_mps[near] - here["wind_e_mps"])))


def read_sounding(path):
    """Read a radiosonde text file (module notes).

    Raises
    ------
    FlightDataError
        No ``ALT DIR SPD ...`` header, or fewer than two rows under it; a row's problem names
        its line.
    OSError
        The file cannot be opened.
    """
    with open(path, encoding="utf-8", errors="replace") as f:
        lines = f.read().splitlines()
    start = next((i for i, line in enumerate(lines) if tuple(line.split()[:7]) == _HEADER), None)
    if start is None:
        raise FlightDataError(f"{path}: no sounding header ({' '.join(_HEADER)} ...)")
    rows = []
    for line_no, line in enumerate(lines[start + 2:], start=start + 3):
        fields = line.split()
        if not fields:
            continue
        try:
            values = [float(v) for v in fields[:7]]
        except ValueError:
            break                    # the end of the table (TERMINATION, MANDATORY LEVELS)
        if len(values) < 7:
            raise FlightDataError(f"{path}: line {line_no}: {len(fields)} fields, at least 7 "
                                  "(ALT DIR SPD SHR TEMP DPT PRESS)")
        rows.append(values)
    if len(rows) < 2:
        raise FlightDataError(f"{path}: fewer than two sounding rows under the header")
    table = np.array(rows)
    table = table[np.argsort(table[:, 0], kind="stable")]
    wind_n, wind_e = wind_vector_mps(table[:, 2] * KT_TO_MPS, table[:, 1])
    return Sounding(alt_m=table[:, 0] * FT_TO_M, wind_n_mps=wind_n, wind_e_mps=wind_e,
                    temp_k=table[:, 4] + 273.15, ps_pa=table[:, 6] * PA_PER_UNIT["mb"],
                    source=str(path), title=" / ".join(x.strip() for x in lines[:start] if
                                                        x.strip()))
