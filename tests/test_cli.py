"""The hunting command: models listing, simulate, errors."""
import json
import subprocess
import sys

from hunting.cli import main


def test_models_lists_presets_with_units(capsys):
    assert main(["models"]) == 0
    out = capsys.readouterr().out
    for name in ("table9.1", "table8.1-switch", "table8.1-lugre", "limms-switch", "limms-lugre"):
        assert name in out
    assert "Fs" in out and "[N m]" in out and "[m/s]" in out


def test_simulate_writes_json_and_plot(tmp_path):
    js, png = tmp_path / "t.json", tmp_path / "t.png"
    assert main(["simulate", "table9.1", "--x0", "0.1,0,0", "--t", "3", "--json", str(js), "--plot", str(png)]) == 0
    data = json.loads(js.read_text())
    assert data["status"] == "SUCCESS" and abs(data["events"]["x"][1][0] + 0.1222757) < 1e-6
    assert png.stat().st_size > 10000


def test_bad_set_is_reported_not_raised(capsys):
    assert main(["simulate", "table9.1", "--set", "m=-1"]) == 2
    assert "mass = -1.0 is not allowed" in capsys.readouterr().err


def test_console_script_entry_point_runs():
    r = subprocess.run([sys.executable, "-m", "hunting.cli", "models"], capture_output=True, text=True)
    assert r.returncode == 0 and "table9.1" in r.stdout
