"""The mismatch analysis: where a recording and a nominal model disagree, and which physics the
model leaves out (``learn mismatch --recording``; the method in ``docs/mismatch.md``)."""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path

import numpy as np

from . import _native

#: The files an analysis writes, as ``learn mismatch --out`` does.
ANALYSIS_FILES = ("mismatch.json", "mismatch.svg", "mismatch.md")


def _check_out(out: Path, overwrite: bool) -> None:
    """Proves the folder writable and refuses to replace files unless ``overwrite``, before any work."""
    out.mkdir(parents=True, exist_ok=True)
    for name in ANALYSIS_FILES:
        target = out / name
        if target.exists() and not overwrite:
            raise _native.LearnSysidError(f"{target}: exists; pass overwrite=True to replace it")
        if target.is_dir():
            raise _native.LearnSysidError(f"{target}: is a folder, not a file")
    with tempfile.NamedTemporaryFile(dir=out, prefix=".learn-staging-"):
        pass


def _write(out: Path, contents) -> None:
    """Writes the files into a staging folder in ``out``, then moves each into place."""
    staging = Path(tempfile.mkdtemp(dir=out, prefix=".learn-staging-"))
    try:
        for name, text in zip(ANALYSIS_FILES, contents):
            (staging / name).write_text(text, encoding="utf-8")
        for name in ANALYSIS_FILES:
            os.replace(staging / name, out / name)
    finally:
        shutil.rmtree(staging, ignore_errors=True)


#: The Neural-Fly layout's columns a recording given as arrays may hold: one value per row
#: (scalars) or a vector per row (``R`` a 3 × 3 matrix, ``pwm`` one command per rotor).
SCALAR_COLUMNS = ("t", "T_sp", "hover_throttle", "battery_voltage")
VECTOR_COLUMNS = ("p", "v", "w", "q", "R", "pwm", "p_d", "v_d", "q_sp")


def _cell(values) -> str:
    """A list cell as the Neural-Fly files write them, every number exact (``repr``)."""
    if np.ndim(values) == 0:
        return repr(float(values))
    return '"' + _nested(values) + '"'


def _nested(values) -> str:
    if np.ndim(values) == 0:
        return repr(float(values))
    return "[" + ", ".join(_nested(v) for v in values) + "]"


def write_recording(path, columns: dict) -> None:
    """Writes arrays (``t``, ``p``, ``v``, ``w``, ``q`` or ``R``, ``T_sp``, ``hover_throttle``,
    ``pwm``; optionally ``battery_voltage``, ``p_d``, ``v_d``, ``q_sp``) as a recording in the
    Neural-Fly layout, one row per sample, the numbers exact. ``learn mismatch --recording``
    and ``learn data inspect`` read it."""
    unknown = sorted(set(columns) - set(SCALAR_COLUMNS) - set(VECTOR_COLUMNS))
    if unknown:
        raise _native.LearnSysidError(f"recording arrays: unknown column(s) {', '.join(unknown)}")
    names = [name for name in SCALAR_COLUMNS + VECTOR_COLUMNS if name in columns]
    arrays = {name: np.asarray(columns[name], dtype=np.float64) for name in names}
    rows = {len(array) for array in arrays.values()}
    if len(rows) != 1:
        sizes = ", ".join(f"{name} {len(array)}" for name, array in arrays.items())
        raise _native.LearnSysidError(f"recording arrays: the columns have different numbers of rows ({sizes})")
    with open(path, "w", encoding="utf-8") as file:
        file.write(",".join(names) + "\n")
        for k in range(rows.pop()):
            file.write(",".join(_cell(arrays[name][k]) for name in names) + "\n")


def analyze(recording, model, *, layout=None, rows=None, out=None, overwrite=False, half_width=None, part_rows=None,
            progress=None) -> dict:
    """Analyses ``recording`` (a path: the Neural-Fly layout, or any CSV, Parquet or ULog file
    that ``layout`` maps; or a dict of arrays, written as :func:`write_recording` writes them to
    a temporary file, which the report names) against ``model`` (a nominal-model JSON file's path, or the same as a
    dict). Returns ``mismatch.json``'s content as a dict (the named effects with their
    parameters and standard errors, the located windows, the held-out fit); with ``out``, also
    writes ``mismatch.{json,svg,md}`` there, as ``learn mismatch --out`` does. A recording
    longer than ``part_rows`` rows (40,000 by default) is analysed in parts; ``rows=(start,
    end)`` takes only those data rows (``--rows``), ``half_width`` the test function's half
    width in seconds (``--half-width``). The interpreter is released while the analysis runs;
    ``progress(message)`` (e.g. ``print``) is told each stage, as the CLI's spinner."""
    model_path = model_json = None
    if isinstance(model, dict):
        model_json = json.dumps(model)
    else:
        model_path = os.fspath(model)
    folder = Path(out) if out is not None else None
    if folder is not None:
        _check_out(folder, overwrite)
    if isinstance(recording, dict):
        if layout is not None:
            raise _native.LearnSysidError("a recording given as arrays is in the Neural-Fly layout: give no layout")
        with tempfile.TemporaryDirectory(prefix="learn-sysid-") as scratch:
            path = Path(scratch) / "recording.csv"
            write_recording(path, recording)
            return _analyze(path, folder, model_path, model_json, None, half_width, part_rows, rows, progress)
    return _analyze(recording, folder, model_path, model_json, layout, half_width, part_rows, rows, progress)


def _analyze(recording, folder, model_path, model_json, layout, half_width, part_rows, rows, progress) -> dict:
    contents = _native.analyze_mismatch(
        os.fspath(recording),
        os.fspath(folder) if folder is not None else ".",
        model_path=model_path,
        model_json=model_json,
        layout=None if layout is None else os.fspath(layout),
        half_width=half_width,
        part_rows=part_rows,
        rows=None if rows is None else (int(rows[0]), int(rows[1])),
        progress=progress,
    )
    if folder is not None:
        _write(folder, contents)
    return json.loads(contents[0])
