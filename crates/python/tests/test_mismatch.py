"""The mismatch analysis from Python gives the CLI's files and numbers; bad input is one line."""

import json
import shutil

import pytest

import learn_sysid as ls


@pytest.fixture(scope="module")
def flight(tmp_path_factory, root, learn_binary):
    import subprocess

    folder = tmp_path_factory.mktemp("mismatch")
    shutil.copy(root / "experiments/mismatch/vehicles/quad-a.json", folder / "quad.json")
    scenario = json.loads((root / "experiments/mismatch/configurations/a.json").read_text())
    scenario.update(model="quad.json", duration_s=30.0, effects={"linear_drag": {"d": [0.35, 0.35, 0.1]}})
    (folder / "scenario.json").write_text(json.dumps(scenario))
    for args in (["simulate", "--scenario", "scenario.json", "--out", "flight.csv"],
                 ["mismatch", "--recording", "flight.csv", "--model", "quad.json", "--out", "cli"]):
        result = subprocess.run([str(learn_binary), "--quiet", *args], cwd=folder, capture_output=True, text=True)
        assert result.returncode == 0, result.stderr
    return folder


def test_the_analysis_equals_the_cli(flight, monkeypatch):
    monkeypatch.chdir(flight)
    report = ls.analyze("flight.csv", "quad.json", out="python")
    for name in ls.ANALYSIS_FILES:
        assert (flight / "python" / name).read_text() == (flight / "cli" / name).read_text(), name
    assert [effect["id"] for effect in report["effects"]] == ["linear_drag"]
    assert report == json.loads((flight / "cli" / "mismatch.json").read_text())
    with pytest.raises(ls.LearnSysidError, match="exists"):
        ls.analyze("flight.csv", "quad.json", out="python")
    assert not list((flight / "python").glob(".learn-staging-*"))


def test_a_model_given_as_a_dict_names_the_same_effects(flight):
    model = json.loads((flight / "quad.json").read_text())
    stages = []
    report = ls.analyze(flight / "flight.csv", model, progress=stages.append)
    assert stages and stages[0].startswith("pass 1: ")
    expected = json.loads((flight / "cli" / "mismatch.json").read_text())
    assert [e["id"] for e in report["effects"]] == [e["id"] for e in expected["effects"]]
    assert report["effects"][0]["parameters"] == expected["effects"][0]["parameters"]


def read_columns(path):
    """The recording's columns as arrays (list cells are JSON)."""
    import csv

    import numpy as np

    with open(path, newline="") as file:
        rows = list(csv.DictReader(file))
    return {name: np.array([json.loads(row[name]) for row in rows]) for name in rows[0] if name}


def test_a_recording_given_as_arrays_gives_the_same_analysis(flight):
    columns = read_columns(flight / "flight.csv")
    assert set(columns) >= {"t", "p", "v", "w", "q", "R", "T_sp", "hover_throttle", "pwm"}
    report = ls.analyze(columns, flight / "quad.json")
    expected = json.loads((flight / "cli" / "mismatch.json").read_text())
    assert report["effects"] == expected["effects"]
    assert report["fit"] == expected["fit"]
    with pytest.raises(ls.LearnSysidError, match="different numbers of rows"):
        ls.analyze({**columns, "t": columns["t"][:-1]}, flight / "quad.json")
    with pytest.raises(ls.LearnSysidError, match="unknown column"):
        ls.analyze({**columns, "speed": columns["t"]}, flight / "quad.json")


def test_bad_input_raises_one_line_errors(flight, tmp_path):
    with pytest.raises(ls.LearnSysidError, match="absent.csv"):
        ls.analyze(tmp_path / "absent.csv", flight / "quad.json")
    model = json.loads((flight / "quad.json").read_text())
    model["mass_kg"] = -1.0
    with pytest.raises(ls.LearnSysidError) as error:
        ls.analyze(flight / "flight.csv", model)
    assert "mass" in str(error.value) and "\n" not in str(error.value)
    with pytest.raises(ls.LearnSysidError, match="part"):
        ls.analyze(flight / "flight.csv", flight / "quad.json", part_rows=10)
    # The CLI's --rows message: one reading of a recording serves both.
    with pytest.raises(ls.LearnSysidError, match=r"flight.csv: rows 10:99999 reach past its \d+ data rows"):
        ls.analyze(flight / "flight.csv", flight / "quad.json", rows=(10, 99999))


def test_the_jmavsim_log_gives_the_committed_analysis(root, tmp_path, monkeypatch):
    # A PX4 ULog through its layout, as `make mismatch-demo` analyses it into results/.
    monkeypatch.chdir(root)
    report = ls.analyze(
        "data/ulog/sample_px4_events.ulg",
        "experiments/mismatch/vehicles/jmavsim-iris.json",
        layout="experiments/layouts/px4-ulog.json",
        half_width=0.4,
        rows=(186, 262),
        out=tmp_path / "jmavsim",
    )
    committed = root / "results/mismatch/shared/jmavsim"
    assert report == json.loads((committed / "mismatch.json").read_text())
    assert (tmp_path / "jmavsim" / "mismatch.svg").read_text() == (committed / "mismatch.svg").read_text()
