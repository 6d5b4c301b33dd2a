"""hunting.datasets and ``hunting data``: the EMPS files found, fetched and verified.

Most tests use small stand-in files whose hashes replace the published ones (they run
everywhere); the fetch goes to a local HTTP server (the network is not needed). The tests on
the real files skip when the shared data directory is absent."""
import contextlib
import functools
import hashlib
import http.server
import json
import os
import shlex
import socket
import threading
import zipfile
from pathlib import Path

import pytest

import hunting.datasets as ds
from hunting.cli import build_parser, main

ROOT = Path(__file__).resolve().parents[1]
FILES = ("DATA_EMPS.mat", "DATA_EMPS_PULSES.mat")


def _real_emps_dir() -> Path | None:
    """The published files on this machine: $HUNTING_DATA/emps or ../shared/data/emps."""
    for d in ([Path(os.environ["HUNTING_DATA"]) / "emps"] if os.environ.get("HUNTING_DATA") else []) + \
             [ROOT.parent / "shared" / "data" / "emps"]:
        if all((d / f).is_file() for f in FILES):
            return d
    return None


REAL = _real_emps_dir()
needs_real = pytest.mark.skipif(REAL is None, reason="the EMPS files are absent (set HUNTING_DATA to a "
                                "directory holding emps/DATA_EMPS.mat, or keep ../shared/data/emps beside the checkout)")


@pytest.fixture
def isolated(tmp_path, monkeypatch):
    """No data anywhere: HUNTING_DATA unset, an empty cache, a working directory with no
    ../shared, and no checkout to look beside."""
    monkeypatch.delenv("HUNTING_DATA", raising=False)
    monkeypatch.setenv("HUNTING_CACHE_DIR", str(tmp_path / "cache"))
    work = tmp_path / "top" / "work"
    work.mkdir(parents=True)
    monkeypatch.chdir(work)
    monkeypatch.setattr(ds, "_project_root", lambda: None)
    return tmp_path


@pytest.fixture
def fake(isolated, monkeypatch):
    """Stand-in files (bytes -> name) whose hashes are made the published ones."""
    content = {name: f"stand-in for {name}\n".encode() * 100 for name in FILES}
    monkeypatch.setattr(ds, "EMPS_SHA256", {n: hashlib.sha256(b).hexdigest() for n, b in content.items()})
    return content


def _write(d: Path, content: dict) -> Path:
    d.mkdir(parents=True, exist_ok=True)
    for name, data in content.items():
        (d / name).write_bytes(data)
    return d


@contextlib.contextmanager
def serve(directory: Path):
    """A local HTTP server for ``directory``; yields its base URL."""
    handler = functools.partial(http.server.SimpleHTTPRequestHandler, directory=str(directory))
    handler.log_message = lambda *a, **k: None
    with http.server.ThreadingHTTPServer(("127.0.0.1", 0), handler) as srv:
        t = threading.Thread(target=srv.serve_forever, daemon=True)
        t.start()
        try:
            yield f"http://127.0.0.1:{srv.server_address[1]}"
        finally:
            srv.shutdown()
            t.join(5)


def _zip(path: Path, content: dict, folder: str = "EMPS") -> Path:
    path.parent.mkdir(parents=True, exist_ok=True)
    with zipfile.ZipFile(path, "w") as z:
        for name, data in content.items():
            z.writestr(f"{folder}/{name}", data)
        z.writestr(f"{folder}/README.txt", "other members are ignored")
    return path


def _closed_port_url() -> str:
    with socket.socket() as s:
        s.bind(("127.0.0.1", 0))
        port = s.getsockname()[1]
    return f"http://127.0.0.1:{port}/EMPS.zip"      # nothing listens there: connection refused


# ---------------------------------------------------------------- look-up
def test_hunting_data_both_layouts(fake, isolated, monkeypatch):
    _write(isolated / "d1" / "emps", fake)
    monkeypatch.setenv("HUNTING_DATA", str(isolated / "d1"))
    got = ds.emps(download=False)
    assert got.fit == isolated / "d1" / "emps" / "DATA_EMPS.mat"
    assert got.validate.read_bytes() == fake["DATA_EMPS_PULSES.mat"]
    _write(isolated / "d2", fake)                                   # the files directly in it
    monkeypatch.setenv("HUNTING_DATA", str(isolated / "d2"))
    assert ds.emps(download=False).fit == isolated / "d2" / "DATA_EMPS.mat"


def test_shared_directory_beside_the_working_directory(fake, isolated):
    d = _write(isolated / "top" / "shared" / "data" / "emps", fake)
    assert ds.emps(download=False).fit.resolve() == (d / "DATA_EMPS.mat").resolve()


def test_shared_directory_beside_the_checkout(fake, isolated, monkeypatch):
    d = _write(isolated / "repo" / "shared" / "data" / "emps", fake)
    monkeypatch.setattr(ds, "_project_root", lambda: isolated / "repo" / "checkout")
    assert ds.emps(download=False).validate == d / "DATA_EMPS_PULSES.mat"


def test_a_directory_with_one_file_is_passed_over(fake, isolated, monkeypatch):
    _write(isolated / "half", {"DATA_EMPS.mat": fake["DATA_EMPS.mat"]})
    full = _write(isolated / "top" / "shared" / "data" / "emps", fake)
    monkeypatch.setenv("HUNTING_DATA", str(isolated / "half"))
    assert ds.emps(download=False).fit.resolve() == (full / "DATA_EMPS.mat").resolve()


def test_a_local_copy_that_differs_is_named_with_both_hashes(fake, isolated, monkeypatch):
    bad = dict(fake, **{"DATA_EMPS_PULSES.mat": b"changed"})
    _write(isolated / "d", bad)
    monkeypatch.setenv("HUNTING_DATA", str(isolated / "d"))
    with pytest.raises(ds.ChecksumError) as e:
        ds.emps()
    msg = str(e.value)
    assert "DATA_EMPS_PULSES.mat" in msg and ds.EMPS_SHA256["DATA_EMPS_PULSES.mat"] in msg
    assert hashlib.sha256(b"changed").hexdigest() in msg
    assert (isolated / "d" / "DATA_EMPS_PULSES.mat").read_bytes() == b"changed"     # left as it is


def test_hunting_data_without_the_files_is_said(fake, isolated, monkeypatch, caplog):
    monkeypatch.setenv("HUNTING_DATA", str(isolated))
    with pytest.raises(ds.DataError, match=r"\$HUNTING_DATA"):
        ds.emps(download=False)
    assert f"HUNTING_DATA={isolated} holds no DATA_EMPS.mat and DATA_EMPS_PULSES.mat" in caplog.text


def test_nothing_local_and_no_download(fake):
    with pytest.raises(ds.DataError, match="HUNTING_DATA") as e:
        ds.emps(download=False)
    assert ds.EMPS_URL in str(e.value) and "\n" not in str(e.value)


# ---------------------------------------------------------------- fetch
def test_fetch_from_a_server_then_offline_from_the_cache(fake, isolated):
    _zip(isolated / "srv" / "EMPS.zip", fake)
    with serve(isolated / "srv") as base:
        got = ds.emps(url=f"{base}/EMPS.zip")
    cache = isolated / "cache" / "data" / "emps"
    assert got.fit == cache / "DATA_EMPS.mat" and got.fit.read_bytes() == fake["DATA_EMPS.mat"]
    assert sorted(p.name for p in cache.iterdir()) == sorted(FILES)           # nothing else left
    assert ds.emps(url=_closed_port_url()) == got                             # no network needed now


def test_fetch_with_a_checksum_mismatch(fake, isolated):
    bad = dict(fake, **{"DATA_EMPS.mat": b"not the published file"})
    _zip(isolated / "srv" / "EMPS.zip", bad)
    with serve(isolated / "srv") as base, pytest.raises(ds.ChecksumError) as e:
        ds.emps(url=f"{base}/EMPS.zip")
    msg = str(e.value)
    assert f"DATA_EMPS.mat downloaded from {base}/EMPS.zip" in msg
    assert f"expected {ds.EMPS_SHA256['DATA_EMPS.mat']}" in msg
    assert f"sha256 {hashlib.sha256(b'not the published file').hexdigest()}" in msg
    assert list((isolated / "cache" / "data" / "emps").iterdir()) == []       # the download discarded


def test_fetch_without_network_says_what_to_do(fake):
    url = _closed_port_url()
    with pytest.raises(ds.DataError) as e:
        ds.emps(url=url)
    msg = str(e.value)
    assert "\n" not in msg and "Connection refused" in msg
    assert "set HUNTING_DATA" in msg and f"download {url}" in msg


def test_fetch_of_a_missing_url_or_an_archive_without_the_files(fake, isolated):
    _zip(isolated / "srv" / "other.zip", {"something.mat": b"x"})
    with serve(isolated / "srv") as base:
        with pytest.raises(ds.DataError, match="HTTP 404"):
            ds.emps(url=f"{base}/EMPS.zip")
        with pytest.raises(ds.DataError, match="holds no DATA_EMPS.mat, DATA_EMPS_PULSES.mat"):
            ds.emps(url=f"{base}/other.zip")


# ---------------------------------------------------------------- the command
def _run(capsys, *argv):
    code = main(list(argv))
    out, err = capsys.readouterr()
    assert "Traceback" not in out + err
    return code, out, err


def test_command_puts_data_and_model_and_prints_the_diagnose_command(fake, isolated, monkeypatch, capsys):
    src = _write(isolated / "src" / "emps", fake)
    monkeypatch.setenv("HUNTING_DATA", str(isolated / "src"))
    code, out, err = _run(capsys, "data", "emps", "--dir", "out dir")
    assert code == 0, err
    d = Path("out dir")
    for name, data in fake.items():
        assert (d / name).read_bytes() == data and (src / name).read_bytes() == data
    assert (d / "emps_model.json").read_text() == ds.emps_model_json()
    cmd = out.strip().splitlines()[-1].strip()
    assert cmd == ("hunting diagnose 'out dir/DATA_EMPS.mat' --validate 'out dir/DATA_EMPS_PULSES.mat' "
                   "--model 'out dir/emps_model.json'")
    args = build_parser().parse_args(shlex.split(cmd)[1:])           # the diagnose command's own flags
    assert (args.cmd, args.data, args.validate, args.model) == (
        "diagnose", "out dir/DATA_EMPS.mat", "out dir/DATA_EMPS_PULSES.mat", "out dir/emps_model.json")
    assert _run(capsys, "data", "emps", "--dir", "out dir")[1].count("kept (same content)") == 3


def test_command_default_directory_and_refusing_to_overwrite(fake, isolated, monkeypatch, capsys):
    monkeypatch.setenv("HUNTING_DATA", str(_write(isolated / "src", fake)))
    assert _run(capsys, "data", "emps")[0] == 0
    assert Path("DATA_EMPS.mat").read_bytes() == fake["DATA_EMPS.mat"]
    Path("emps_model.json").write_text("{}")
    code, out, err = _run(capsys, "data", "emps")
    assert code == 2 and err.count("\n") == 1 and "emps_model.json" in err and "--force" in err
    assert Path("emps_model.json").read_text() == "{}"
    assert _run(capsys, "data", "emps", "--force")[0] == 0
    assert Path("emps_model.json").read_text() == ds.emps_model_json()


@pytest.mark.parametrize("argv, expect", [
    (["data", "emps", "--dir", "plain"], "exists and is not a directory"),
    (["data", "emps", "--dir", "/proc/nope"], "cannot be created"),
    (["data", "nope"], "invalid choice"),
])
def test_command_bad_arguments(fake, isolated, capsys, argv, expect):
    Path("plain").write_text("x")
    code, out, err = _run(capsys, *argv)
    assert code == 2 and err.startswith("hunting: error: ") and err.count("\n") == 1 and expect in err, err


def test_command_without_data_or_network(fake, isolated, monkeypatch, capsys):
    monkeypatch.setattr(ds, "EMPS_URL", _closed_port_url())
    code, out, err = _run(capsys, "data", "emps")
    assert code == 2 and err.count("\n") == 1 and "set HUNTING_DATA" in err and ds.EMPS_URL in err, err
    assert not Path("DATA_EMPS.mat").exists()


def test_command_with_a_corrupt_copy(fake, isolated, monkeypatch, capsys):
    monkeypatch.setenv("HUNTING_DATA", str(_write(isolated / "src", dict(fake, **{"DATA_EMPS.mat": b"x"}))))
    code, out, err = _run(capsys, "data", "emps")
    assert code == 2 and err.count("\n") == 1 and ds.EMPS_SHA256["DATA_EMPS.mat"] in err, err
    assert not Path("DATA_EMPS.mat").exists()


# ---------------------------------------------------------------- the example model
def test_example_model_is_the_published_symmetric_model():
    from hunting.diagnose import NominalModel
    m = NominalModel.from_dict(json.loads(ds.emps_model_json()))
    assert (m.mass, m.cm, m.offset) == (95.1089, 35.15065188, 0.0)
    assert (m.curve.positive.Fc, m.curve.positive.b) == (20.3935, 203.5034)
    assert m.controller["type"] == "pd-velocity-loop" and m.controller["kp"] == 160.18
    example = ROOT / "examples" / "emps" / "model.json"
    if example.is_file():                   # the same model in the examples, kept identical
        assert json.loads(example.read_text()) == json.loads(ds.emps_model_json())


def test_example_model_is_package_data():
    import tomllib
    cfg = tomllib.loads((ROOT / "pyproject.toml").read_text())
    assert "*.json" in cfg["tool"]["setuptools"]["package-data"]["hunting.datasets"]
    assert any(d.startswith("pooch") for d in cfg["project"]["dependencies"])


# ---------------------------------------------------------------- the published files
@needs_real
def test_the_published_files_verify():
    for name, digest in ds.EMPS_SHA256.items():
        assert ds.sha256(REAL / name) == digest


@needs_real
def test_fetch_of_the_published_files(isolated):
    content = {name: (REAL / name).read_bytes() for name in FILES}
    _zip(isolated / "srv" / "EMPS.zip", content)
    with serve(isolated / "srv") as base:
        got = ds.emps(url=f"{base}/EMPS.zip")
    assert [ds.sha256(p) for p in got] == [ds.EMPS_SHA256[n] for n in FILES]
    from scipy.io import loadmat
    assert loadmat(got.validate)["pulses_N"].shape == (24841, 1)
