"""The mismatch analysis: where a recording and a nominal model disagree, and which physics the
model leaves out (``learn mismatch --recording``; the method in ``docs/mismatch.md``)."""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path

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


def analyze(recording, model, *, layout=None, out=None, overwrite=False, half_width=None, part_rows=None) -> dict:
    """Analyses ``recording`` (a path: the Neural-Fly layout, or any CSV, Parquet or ULog file
    that ``layout`` maps) against ``model`` (a nominal-model JSON file's path, or the same as a
    dict). Returns ``mismatch.json``'s content as a dict (the named effects with their
    parameters and standard errors, the located windows, the held-out fit); with ``out``, also
    writes ``mismatch.{json,svg,md}`` there, as ``learn mismatch --out`` does. A recording
    longer than ``part_rows`` rows (40,000 by default) is analysed in parts. The interpreter is
    released while the analysis runs."""
    model_path = model_json = None
    if isinstance(model, dict):
        model_json = json.dumps(model)
    else:
        model_path = os.fspath(model)
    folder = Path(out) if out is not None else None
    if folder is not None:
        _check_out(folder, overwrite)
    contents = _native.analyze_mismatch(
        os.fspath(recording),
        os.fspath(folder) if folder is not None else ".",
        model_path=model_path,
        model_json=model_json,
        layout=None if layout is None else os.fspath(layout),
        half_width=half_width,
        part_rows=part_rows,
    )
    if folder is not None:
        _write(folder, contents)
    return json.loads(contents[0])
