"""LeARN from Python: the same model as `learn meta-train --tasks` on the same tasks, adaptation,
prediction, explanation, checkpoints both ways, the NumPy reader, bad input."""

import json

import numpy as np
import pytest

import learn_sysid as ls

CONFIG = {"hidden_layers": [8, 8], "meta_training": {"iterations": 60}, "adaptation": {"passes": 2, "step": 0.01}}
DRAWS = [(0.5, 0.1), (1.5, 0.3), (2.5, 0.2), (3.5, 0.4)]


def oscillator(k, c, rows=200, dt=0.05):
    """x'' = −k x − c x' + cos(1.3 t), ten Euler substeps per row: columns x, v, u."""
    x, v, h, out = 0.5, 0.0, dt / 10, []
    for row in range(rows):
        t = row * dt
        out.append((x, v, np.cos(1.3 * t)))
        for step in range(10):
            force = np.cos(1.3 * (t + step * h))
            v += h * (-k * x - c * v + force)
            x += h * v
    return np.array(out)


@pytest.fixture(scope="module")
def trained(tmp_path_factory):
    folder = tmp_path_factory.mktemp("learn")
    config = folder / "small.json"
    config.write_text(json.dumps(CONFIG))
    tasks = [oscillator(k, c) for k, c in DRAWS]
    model = ls.LeARN.meta_train(tasks, ["x", "v"], ["u"], interval=0.05, config=config, seed=3)
    return folder, config, tasks, model


def test_python_and_the_cli_meta_train_the_same_parameters(trained, run_learn, monkeypatch):
    folder, _, tasks, model = trained
    monkeypatch.chdir(folder)
    for i, task in enumerate(tasks):
        times = np.arange(task.shape[0]) * 0.05
        np.savetxt(folder / f"train-{i}.csv", np.column_stack([times, task]), delimiter=",",
                   header="t,x,v,u", comments="", fmt="%.17g")
    run_learn("meta-train", "--tasks", "train-*.csv", "--state", "x,v", "--control", "u",
              "--config", "small.json", "--seed", "3", "--out", "cli.json", cwd=folder)
    from_cli = json.loads((folder / "cli.json").read_text())
    # the CLI reads the interval off the time column (0.05 to rounding): given the same, the same bits
    interval = from_cli["trained_on"]["sampling_interval"]
    same_inputs = ls.LeARN.meta_train(tasks, ["x", "v"], ["u"], interval=interval, config="small.json", seed=3)
    same_inputs.save(folder / "python.json")
    from_python = json.loads((folder / "python.json").read_text())
    assert from_python["parameters"] == from_cli["parameters"]
    assert from_python["meta_loss_history"] == from_cli["meta_loss_history"]
    # from the same files, the same checkpoint as the CLI's, byte for byte
    ls.LeARN.meta_train_files("train-*.csv", ["x", "v"], ["u"], config="small.json", seed=3).save(folder / "files.json")
    assert (folder / "files.json").read_bytes() == (folder / "cli.json").read_bytes()
    cli_model = ls.LeARN.load(folder / "cli.json")
    assert cli_model.input_names == ["x", "v", "u"] and cli_model.output_names == ["x'", "v'"]
    assert model.seed == 3 and model.interval == 0.05 and len(model.meta_loss_history) == 60


def test_adaptation_lowers_the_error_and_the_cli_agrees(trained, run_learn):
    folder, _, _, model = trained
    unseen = oscillator(2.0, 0.25, rows=300)
    result = model.evaluate(unseen, support=(0, 150), query=(150, 300))
    assert result["adaptation_mse"] < result["meta_trained_support_mse"]
    theta = model.adapt(unseen, (0, 150))
    np.testing.assert_array_equal(theta, result["adapted_parameters"])
    adapted = model.predict(unseen[150:], parameters=theta)
    assert adapted.shape == (150, 2)
    model.save(folder / "for-cli.json")
    np.savetxt(folder / "unseen.csv", np.column_stack([np.arange(300) * 0.05, unseen]), delimiter=",",
               header="t,x,v,u", comments="", fmt="%.17g")
    out = run_learn("evaluate", "--model", "for-cli.json", "--csv", "unseen.csv", "--support-rows", "0:150",
                    "--query-rows", "150:300", "--json", cwd=folder)
    cli = json.loads(out.stdout)
    assert cli["learn"]["adapt"] == pytest.approx(result["adaptation_mse"], rel=1e-12)
    assert cli["learn"]["gen"] == pytest.approx(result["generalisation_mse"], rel=1e-12)


def test_the_explanation_equals_the_cli(trained, run_learn):
    folder, _, _, model = trained
    unseen = oscillator(2.0, 0.25, rows=300)
    explanation = model.explain(unseen, support=(0, 150))
    assert [o["output"] for o in explanation["outputs"]] == ["x'", "v'"]
    model.save(folder / "explained.json")
    np.savetxt(folder / "explained.csv", np.column_stack([np.arange(300) * 0.05, unseen]), delimiter=",",
               header="t,x,v,u", comments="", fmt="%.17g")
    run_learn("explain", "explained.json", "--csv", "explained.csv", "--support-rows", "0:150",
              "--json", "explanation.json", cwd=folder)
    cli = json.loads((folder / "explanation.json").read_text())["explanation"]
    assert [o["equation"] for o in explanation["outputs"]] == [o["equation"] for o in cli["outputs"]]
    for ours, theirs in zip(explanation["outputs"], cli["outputs"]):
        assert [i["input"] for i in ours["inputs"]] == [i["input"] for i in theirs["inputs"]]
        for a, b in zip(ours["inputs"], theirs["inputs"]):
            assert a["mean_abs_coefficient"] == pytest.approx(b["mean_abs_coefficient"], rel=1e-9)


def test_the_numpy_reader_reproduces_the_predictions(trained, tmp_path):
    _, _, _, model = trained
    model.save(tmp_path / "model.json")
    inputs = oscillator(2.0, 0.25, rows=120)
    weights = ls.read_checkpoint(tmp_path / "model.json")
    assert weights["library"][0][0].shape == (3, 8)
    np.testing.assert_allclose(ls.numpy_predict(weights, inputs), model.predict(inputs), rtol=1e-12, atol=1e-12)


def test_bad_input_raises_one_line_errors(trained, tmp_path):
    _, config, tasks, model = trained
    with pytest.raises(ls.LearnSysidError, match="columns"):
        ls.LeARN.meta_train([t[:, :2] for t in tasks], ["x", "v"], ["u"], interval=0.05, config=config)
    with pytest.raises(ls.LearnSysidError, match="rows 0:999"):
        model.evaluate(tasks[0], support=(0, 999), query=(0, 10))
    with pytest.raises(ls.LearnSysidError, match="inputs have 2 columns"):
        model.predict(tasks[0][:, :2])
    bad = tmp_path / "bad.json"
    bad.write_text('{"meta_training": {"iterations": -1}}')
    with pytest.raises(ls.LearnSysidError, match="bad.json"):
        ls.LeARN.meta_train(tasks, ["x", "v"], ["u"], interval=0.05, config=bad)
    with pytest.raises(ls.LearnSysidError, match="absent.json"):
        ls.LeARN.load(tmp_path / "absent.json")


def test_progress_is_reported_and_its_exceptions_raised(trained):
    folder, config, tasks, _ = trained
    seen = []
    ls.LeARN.meta_train(tasks, ["x", "v"], ["u"], interval=0.05, config=config, progress=lambda *a: seen.append(a))
    assert seen == [(done, 60) for done in range(1, 61)]

    def stop(done, total):
        raise RuntimeError(f"stopped at {done}")

    with pytest.raises(RuntimeError, match="stopped at 1"):
        ls.LeARN.meta_train(tasks, ["x", "v"], ["u"], interval=0.05, config=config, progress=stop)
