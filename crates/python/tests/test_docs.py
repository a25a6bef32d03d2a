"""The ten-line example of docs/python.md runs as written."""

import re


def test_the_ten_line_example_runs(root, tmp_path, monkeypatch, capsys):
    text = (root / "docs" / "python.md").read_text()
    example = re.search(r"## Ten lines\n\n```python\n(.*?)```", text, re.S).group(1)
    assert len(example.strip().splitlines()) == 10
    monkeypatch.chdir(tmp_path)
    namespace = {}
    exec(compile(example, "docs/python.md", "exec"), namespace)
    printed = capsys.readouterr().out
    assert "(x0)' =  1.000 x1\n" in printed and "(x1)' = -1.000 x0 + -0.189 x1 +  1.000 u0" in printed
    assert (tmp_path / "model.json").is_file()
    xs, x = namespace["xs"], namespace["x"]
    assert xs.shape == (500, 2) and abs(xs - x[:500]).max() < 0.013


def test_the_version_is_the_workspace_crates(root):
    import learn_sysid

    cargo = (root / "Cargo.toml").read_text()
    assert f'version = "{learn_sysid.__version__}"' in cargo
