"""The parameters a run was made with, read from the run directory (never assumed).

Source, in order: `params.json` written by the case runner (JSON object with "case", "scale",
"seed", "np", "variables" (name → string), "rpm", "rho_p", "d_mean", "mesh_dir", "zones_file",
"git_commit"); otherwise the `TSG-PARAMETERS name=value ...` line the case inputs print into
log.lammps. A params.json that exists but cannot be used is an error, not a reason to fall back.
"""
from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field
from pathlib import Path

from .run_files import AnalysisInputError

PARAMS_FILE = "params.json"
PARAMETERS_LINE = re.compile(r"^TSG-PARAMETERS (.*)$", re.MULTILINE)
REQUIRED = {"rpm": "screw speed, rev/min", "rho_p": "particle density, kg/m^3", "d_mean": "mean particle diameter, m"}


@dataclass(frozen=True)
class RunParameters:
    rpm: float  # rev/min
    rho_p: float  # kg/m^3
    d_mean: float  # m
    source: str  # the file the values came from
    variables: dict[str, str] = field(default_factory=dict)
    case: str | None = None
    scale: str | None = None
    seed: int | None = None
    zones_file: str | None = None
    git_commit: str | None = None
    mesh_tolerance: float | None = None  # m (params.json's mesh_tolerance_m)

    @property
    def revolution_s(self) -> float:
        """One screw revolution, s: the period of the flight passage the sensors see."""
        return 60.0 / self.rpm


def _positive(source: str, name: str, value: object) -> float:
    try:
        number = float(value)  # type: ignore[arg-type]
    except (TypeError, ValueError):
        number = math.nan
    if not (math.isfinite(number) and number > 0):
        raise AnalysisInputError(f"{source}: {name} = {value!r} is not allowed: {REQUIRED[name]}, a finite number > 0")
    return number


def _from_json(path: Path) -> RunParameters:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except json.JSONDecodeError as err:
        raise AnalysisInputError(f"{path}: line {err.lineno}: not valid JSON ({err.msg})") from None
    except (OSError, UnicodeDecodeError) as err:
        raise AnalysisInputError(f"{path}: cannot be read ({err})") from None
    if not isinstance(data, dict):
        raise AnalysisInputError(f"{path}: expected a JSON object with rpm, rho_p, d_mean, ...")
    missing = [name for name in REQUIRED if name not in data]
    if missing:
        raise AnalysisInputError(f"{path}: {', '.join(missing)} missing (needed: {', '.join(REQUIRED)})")
    variables = data.get("variables") or {}
    if not isinstance(variables, dict):
        raise AnalysisInputError(f"{path}: variables must be an object name -> value, got {type(variables).__name__}")
    seed = data.get("seed")
    rpm, rho_p, d_mean = (_positive(str(path), name, data[name]) for name in REQUIRED)
    return RunParameters(rpm, rho_p, d_mean, source=str(path),
                         variables={str(k): str(v) for k, v in variables.items()}, case=data.get("case"),
                         scale=data.get("scale"), seed=int(seed) if isinstance(seed, (int, float)) else None,
                         zones_file=data.get("zones_file"), git_commit=data.get("git_commit"),
                         mesh_tolerance=float(data["mesh_tolerance_m"]) if isinstance(data.get("mesh_tolerance_m"), (int, float))
                         else None)


def _from_log(path: Path) -> RunParameters:
    text = path.read_text(encoding="utf-8", errors="replace")
    lines = PARAMETERS_LINE.findall(text)
    if not lines:
        raise AnalysisInputError(f"{path.parent}: no {PARAMS_FILE} and no TSG-PARAMETERS line in log.lammps: the "
                                 f"run's screw speed, density and particle size are unknown")
    values = dict(word.split("=", 1) for word in lines[-1].split() if "=" in word)
    missing = [name for name in REQUIRED if name not in values]
    if missing:
        raise AnalysisInputError(f"{path}: the TSG-PARAMETERS line lacks {', '.join(missing)}")
    source = f"{path} (TSG-PARAMETERS)"
    rpm, rho_p, d_mean = (_positive(source, name, values[name]) for name in REQUIRED)
    return RunParameters(rpm, rho_p, d_mean, source=source,
                         variables=values)


def read_run_parameters(run_dir: Path | str) -> RunParameters:
    run_dir = Path(run_dir)
    if (run_dir / PARAMS_FILE).is_file():
        return _from_json(run_dir / PARAMS_FILE)
    if (run_dir / "log.lammps").is_file():
        return _from_log(run_dir / "log.lammps")
    raise AnalysisInputError(f"{run_dir}: neither {PARAMS_FILE} nor log.lammps: the run's screw speed, density and "
                             "particle size are unknown")
