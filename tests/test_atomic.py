"""Result files: every kind of path is written the right way, and none is replaced that must not be.

Regular files are replaced whole (temporary file + rename, mode kept); symbolic links keep
pointing where they did and their target is written; FIFOs and character devices are written
directly, never renamed over; directories, block devices, sockets and link loops are refused
at the command line's boundary, before any computing."""
import errno
import os
import socket
import stat
import threading
from pathlib import Path

import pytest

from hunting._atomic import OutputPathError, atomic_path, output_target, write_text
from hunting.cli import main


def _umask():
    old = os.umask(0)
    os.umask(old)
    return old


def _names(d: Path):
    return sorted(p.name for p in d.iterdir())


def test_a_regular_file_is_replaced_whole_and_keeps_its_mode(tmp_path):
    f = tmp_path / "r.json"
    f.write_text("old")
    os.chmod(f, 0o640)
    inode = f.stat().st_ino
    write_text(f, "new")
    assert f.read_text() == "new" and stat.S_IMODE(f.stat().st_mode) == 0o640
    assert f.stat().st_ino != inode                 # a new file renamed onto it: atomic
    assert _names(tmp_path) == ["r.json"]           # no temporary left


def test_a_new_file_gets_the_mode_open_would_give(tmp_path):
    write_text(tmp_path / "n.json", "x")
    assert stat.S_IMODE((tmp_path / "n.json").stat().st_mode) == 0o666 & ~_umask()


def test_a_symlink_stays_and_its_target_is_replaced(tmp_path):
    (tmp_path / "sub").mkdir()
    real = tmp_path / "sub" / "real.json"
    real.write_text("old")
    link = tmp_path / "link.json"
    link.symlink_to(real)
    chain = tmp_path / "chain.json"             # a link to the link
    chain.symlink_to("link.json")
    write_text(chain, "new")
    assert chain.is_symlink() and link.is_symlink() and os.readlink(link) == str(real)
    assert real.read_text() == "new" and _names(tmp_path / "sub") == ["real.json"]
    dangling = tmp_path / "dangling.json"
    dangling.symlink_to("made.json")
    write_text(dangling, "created")
    assert dangling.is_symlink() and (tmp_path / "made.json").read_text() == "created"


def test_a_fifo_is_written_directly_to_its_reader(tmp_path):
    ff = tmp_path / "ff"
    os.mkfifo(ff)
    got = []
    reader = threading.Thread(target=lambda: got.append(ff.read_text()), daemon=True)
    reader.start()
    write_text(ff, "through the pipe")
    reader.join(10)
    assert not reader.is_alive() and got == ["through the pipe"]
    assert stat.S_ISFIFO(os.lstat(ff).st_mode) and _names(tmp_path) == ["ff"]


def test_a_fifo_without_a_reader_fails_within_a_bound(tmp_path):
    ff = tmp_path / "ff"
    os.mkfifo(ff)
    with pytest.raises(OutputPathError, match="FIFO that no process read within 0.2 s"):
        with atomic_path(ff, fifo_wait=0.2) as p:
            p.write_text("nobody listens")
    assert stat.S_ISFIFO(os.lstat(ff).st_mode)


def _char_device_in(tmp_path) -> Path:
    """A second node of the null device (1, 3) in a temporary directory: what the code does to
    a character device can be seen here without risking the machine's /dev/null."""
    node = tmp_path / "null"
    try:
        os.mknod(node, stat.S_IFCHR | 0o666, os.makedev(1, 3))
    except (PermissionError, OSError) as e:
        pytest.skip(f"cannot create a device node here ({e})")
    return node


def test_a_character_device_is_written_directly_never_renamed_over(tmp_path):
    node = _char_device_in(tmp_path)
    before = os.lstat(node)
    with atomic_path(node) as p:
        assert p == node                        # the writer gets the device itself
        p.write_text("discarded")
    after = os.lstat(node)
    assert stat.S_ISCHR(after.st_mode) and (after.st_ino, after.st_rdev) == (before.st_ino, before.st_rdev)
    assert _names(tmp_path) == ["null"]


def test_dev_null_stays_a_device(tmp_path):
    """Only after the same code path left a temporary device node alone does this touch /dev/null."""
    node = _char_device_in(tmp_path)
    ino = os.lstat(node).st_ino
    write_text(node, "x")
    assert stat.S_ISCHR(os.lstat(node).st_mode) and os.lstat(node).st_ino == ino   # guard passed
    assert output_target("/dev/null").kind == "stream"
    before = os.lstat("/dev/null")
    assert os.path.exists("/dev/null") and stat.S_ISCHR(before.st_mode)
    write_text("/dev/null", "x")
    after = os.lstat("/dev/null")
    assert os.path.exists("/dev/null") and stat.S_ISCHR(after.st_mode)
    assert (after.st_ino, after.st_rdev) == (before.st_ino, before.st_rdev)


def test_cli_json_to_dev_null_and_a_symlink_and_a_fifo(tmp_path):
    """The reviewer's commands, on a fast preset: the outputs keep their kind."""
    node = _char_device_in(tmp_path)             # first through a temporary node
    ino = os.lstat(node).st_ino
    assert main(["simulate", "table9.1", "--x0", "0.1", "--t", "0.5", "--json", str(node)]) == 0
    assert stat.S_ISCHR(os.lstat(node).st_mode) and os.lstat(node).st_ino == ino
    before = os.lstat("/dev/null")
    assert stat.S_ISCHR(before.st_mode)
    assert main(["simulate", "table9.1", "--x0", "0.1", "--t", "0.5", "--json", "/dev/null",
                 "--plot", "/dev/null"]) == 0
    after = os.lstat("/dev/null")
    assert stat.S_ISCHR(after.st_mode) and after.st_ino == before.st_ino

    real, link = tmp_path / "real.json", tmp_path / "link.json"
    real.write_text("old")
    link.symlink_to(real.name)
    assert main(["simulate", "table9.1", "--x0", "0.1", "--t", "0.5", "--json", str(link)]) == 0
    assert link.is_symlink() and '"status": "SUCCESS"' in real.read_text()

    ff = tmp_path / "ff"
    os.mkfifo(ff)
    got = []
    reader = threading.Thread(target=lambda: got.append(ff.read_text()), daemon=True)
    reader.start()
    assert main(["simulate", "table9.1", "--x0", "0.1", "--t", "0.5", "--json", str(ff)]) == 0
    reader.join(10)
    assert not reader.is_alive() and '"status": "SUCCESS"' in got[0] and stat.S_ISFIFO(os.lstat(ff).st_mode)


@pytest.mark.parametrize("kind", ["dir", "link-to-dir", "loop", "socket", "too-long", "dangling-into-nowhere"])
def test_paths_that_cannot_hold_a_result_are_refused_before_computing(tmp_path, capsys, monkeypatch, kind):
    import hunting.integrate

    def computed(*a, **k):
        raise AssertionError("computed before checking the outputs")
    monkeypatch.setattr(hunting.integrate, "simulate", computed)
    p = tmp_path / "out.json"
    expect = {"dir": "is a directory", "link-to-dir": "is a directory", "loop": "loop of symbolic links",
              "socket": "is a socket", "too-long": "the name is too long",
              "dangling-into-nowhere": "whose directory does not exist"}[kind]
    if kind == "dir":
        p.mkdir()
    elif kind == "link-to-dir":
        (tmp_path / "d").mkdir()
        p.symlink_to("d")
    elif kind == "loop":
        p.symlink_to("other.json")
        (tmp_path / "other.json").symlink_to("out.json")
    elif kind == "socket":
        s = socket.socket(socket.AF_UNIX)
        s.bind(str(p))
        s.close()
    elif kind == "too-long":
        p = tmp_path / ("x" * 300 + ".json")
    else:
        p.symlink_to(tmp_path / "missing" / "out.json")
    code = main(["simulate", "table9.1", "--json", str(p)])
    err = capsys.readouterr().err
    assert code == 2 and err.count("\n") == 1 and expect in err and "--json" in err, err


def test_block_devices_are_refused(tmp_path):
    node = tmp_path / "blk"
    try:
        os.mknod(node, stat.S_IFBLK | 0o600, os.makedev(7, 200))
    except OSError as e:
        pytest.skip(f"cannot create a device node here ({e})")
    with pytest.raises(OutputPathError, match="is a block device") as e:
        write_text(node, "x")
    assert e.value.errno == errno.EINVAL and stat.S_ISBLK(os.lstat(node).st_mode)


def test_a_long_name_that_fits_gets_a_temporary_name_that_fits(tmp_path):
    name = "y" * 250 + ".json"                       # 255 bytes: the limit
    write_text(tmp_path / name, "ok")
    assert (tmp_path / name).read_text() == "ok" and _names(tmp_path) == [name]


def test_a_path_that_became_a_device_while_writing_is_not_replaced(tmp_path):
    f = tmp_path / "r.json"
    f.write_text("old")
    with pytest.raises(OutputPathError, match="changed while the result was written"):
        with atomic_path(f) as tmp:
            tmp.write_text("new")
            f.unlink()
            os.mkfifo(f)                            # someone put a FIFO there meanwhile
    assert stat.S_ISFIFO(os.lstat(f).st_mode) and _names(tmp_path) == ["r.json"]


def test_dev_stdout_is_the_results_stream(capfd):
    """--json /dev/stdout is standard output (like '-'): the summary then goes to stderr."""
    code = main(["simulate", "table9.1", "--x0", "0.1", "--t", "0.5", "--json", "/dev/stdout"])
    out, err = capfd.readouterr()
    assert code == 0 and out.lstrip().startswith("{") and "SUCCESS" in err


def test_dev_null_twice_with_stdout_on_dev_null(tmp_path):
    """`hunting ... --json /dev/null --plot /dev/null > /dev/null` (a CI job's stdout): both
    outputs discarded, exit 0 (a character device is never taken for standard output)."""
    import subprocess
    import sys
    node = _char_device_in(tmp_path)
    ino = os.lstat(node).st_ino
    write_text(node, "x")
    assert stat.S_ISCHR(os.lstat(node).st_mode) and os.lstat(node).st_ino == ino     # guard first
    before = os.lstat("/dev/null")
    env = dict(os.environ, PYTHONPATH=str(Path(__file__).resolve().parents[1]))
    r = subprocess.run([sys.executable, "-m", "hunting.cli", "simulate", "table9.1", "--x0", "0.1", "--t", "0.5",
                        "--json", "/dev/null", "--plot", "/dev/null"], stdout=subprocess.DEVNULL,
                       stderr=subprocess.PIPE, text=True, env=env, timeout=300)
    after = os.lstat("/dev/null")
    assert r.returncode == 0 and r.stderr == "", r.stderr
    assert stat.S_ISCHR(after.st_mode) and after.st_ino == before.st_ino


@pytest.mark.skipif(not os.path.exists("/dev/full"), reason="no /dev/full on this system")
def test_a_device_that_fails_on_write_is_named(capsys):
    code = main(["simulate", "table9.1", "--x0", "0.1,0,0", "--t", "0.5", "--json", "/dev/full"])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 1 and len(err) == 1 and "'/dev/full'" in err[0] and "could not be written" in err[0]
