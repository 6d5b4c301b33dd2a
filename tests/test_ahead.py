"""Kernels compiled ahead in a helper process (hunting.integrate.ahead)."""
import json
import os
import subprocess
import sys
import time
from pathlib import Path

import pytest

from hunting.integrate import ahead

ROOT = Path(__file__).resolve().parents[1]

# the command line inside a listener for numba's compile events (as benchmarks/bench_coldstart.py)
RUNNER = r"""
import contextlib, io, json, sys
from numba.core import event as ev
compiled = []
class Listener(ev.Listener):
    def on_start(self, event):
        d = event.data.get("dispatcher")
        if d is not None:
            compiled.append(d.py_func.__qualname__)
    def on_end(self, event):
        pass
ev.register("numba:compile", Listener())
from hunting.cli import main
out = io.StringIO()
with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
    code = main(sys.argv[1:])
print(json.dumps(dict(code=code, compiled=compiled, out=out.getvalue())))
"""


def _cold_cli(tmp_path, switch: str, *args) -> dict:
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"), HUNTING_CACHE_DIR=str(tmp_path / "models"))
    env[ahead.ENV_SWITCH] = switch
    out = subprocess.run([sys.executable, "-c", RUNNER, *args], env=env, capture_output=True, text=True,
                         timeout=600, check=True)
    return json.loads(out.stdout.strip().splitlines()[-1])


LOCK_FREE_LOAD = r"""
import contextlib
from hunting.integrate import ahead, _kernel as K
@contextlib.contextmanager
def refused(disp, limit=0):
    raise RuntimeError("the kernel lock was taken")
    yield
ahead.kernel_lock = refused
print("loaded" if K.compiled("variational").overloads else "missing")
try:
    K.compiled("lean")
except RuntimeError:
    print("locked")
"""


def _compile_kernels(tmp_path, *kinds):
    """Compile kernels ``kinds`` into the test's fresh numba cache with the helper's program."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    proc = subprocess.Popen([sys.executable, "-m", "hunting.integrate.compile_kernels", *kinds], env=env,
                            stdin=subprocess.PIPE, stdout=subprocess.DEVNULL)   # stdin open: it compiles them all
    try:
        assert proc.wait(timeout=600) == 0
    finally:
        proc.stdin.close()


def test_the_variational_kernel_stands_in_for_the_lean_one_on_a_cold_cycle(tmp_path):
    """A fresh install whose cache holds the variational kernel only (the helper of `hunting
    cycle` compiles it first): the command runs its transient simulation on it and compiles no
    integrate_kernel in its own process, only the model's functions (that the two kernels give
    the same states bit for bit: tests/test_continuation.py)."""
    args = ("cycle", "--model", str(ROOT / "examples" / "belt.json"))
    _compile_kernels(tmp_path, "variational")
    # a whole cache entry loads without the kernel lock (a helper compiling another kernel may
    # hold it for seconds); a kernel not in the cache compiles under it
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    out = subprocess.run([sys.executable, "-c", LOCK_FREE_LOAD], env=env, capture_output=True, text=True,
                         timeout=600)
    assert out.returncode == 0 and out.stdout.split() == ["loaded", "locked"], out.stdout + out.stderr
    res = _cold_cli(tmp_path, "0", *args)
    assert res["code"] == 0, res["out"]
    assert not [q for q in res["compiled"] if "integrate_kernel" in q], res["compiled"]
    assert res["compiled"], "the model's own functions compile in the command's process"
    assert "stable cycle" in res["out"]


def test_the_variational_kernel_stands_in_for_the_lean_one_only_when_it_is_ready_first(monkeypatch):
    """plain_kind: the lean kernel where it is compiled or cached; else the variational one
    where that is, or where the helper compiles it before the lean one; else the lean one.
    While the variational kernel stands in, the lean one's cache is looked up again only every
    LEAN_LOOKUP seconds (a file read), then found."""
    from types import SimpleNamespace

    from hunting.integrate import _kernel as K
    lean, var = SimpleNamespace(overloads={}), SimpleNamespace(overloads={})   # kernels as plain_kind sees them
    monkeypatch.setattr(K, "_DISPATCHERS", dict(K._DISPATCHERS, lean=lean, variational=var))
    names = {id(lean): "lean", id(var): "variational"}
    for cached, queue, kind in [({"lean"}, ("variational", "lean"), "lean"),
                                ({"lean", "variational"}, (), "lean"),
                                ({"variational"}, (), "variational"),
                                (set(), ("variational", "lean"), "variational"),
                                (set(), ("variational",), "variational"),
                                (set(), ("lean", "variational"), "lean"),
                                (set(), ("full",), "lean"),
                                (set(), (), "lean")]:
        monkeypatch.setattr(ahead, "cached", lambda disp, sig: names.get(id(disp)) in cached)
        monkeypatch.setattr(ahead, "queued", lambda: queue)
        assert K.plain_kind() == kind, (cached, queue)
    assert K.plain_kind() == "lean"
    lean.overloads["sig"] = object()                       # compiled in this process: no lookup at all
    monkeypatch.setattr(ahead, "cached", lambda disp, sig: pytest.fail("looked up a compiled kernel"))
    assert K.plain_kind() == "lean"
    lean.overloads.clear()
    var.overloads["sig"] = object()                        # standing in, the lean kernel not cached
    lookups = []
    monkeypatch.setattr(ahead, "cached", lambda disp, sig: lookups.append(names[id(disp)]) or False)
    monkeypatch.setattr(K, "_lean_looked_up", -float("inf"))
    assert [K.plain_kind() for _ in range(50)] == ["variational"] * 50
    assert lookups == ["lean"]
    monkeypatch.setattr(ahead, "cached", lambda disp, sig: names[id(disp)] == "lean")   # the helper cached it
    monkeypatch.setattr(K, "_lean_looked_up", K._lean_looked_up - K.LEAN_LOOKUP)
    assert K.plain_kind() == "lean"


def test_no_helper_when_switched_off_with_one_core_or_cached(monkeypatch):
    from hunting.integrate import _kernel as K
    targets = {"lean": (K._DISPATCHERS["lean"], K.KERNEL_SIG)}
    monkeypatch.setattr(ahead, "cached", lambda disp, sig: False)
    monkeypatch.setenv(ahead.ENV_SWITCH, "0")
    assert ahead.start(targets) is False
    monkeypatch.setenv(ahead.ENV_SWITCH, "1")
    monkeypatch.setattr(ahead, "_cores", lambda: 1)
    assert ahead.start(targets) is False
    monkeypatch.setattr(ahead, "_cores", lambda: 2)
    monkeypatch.setattr(ahead, "cached", lambda disp, sig: True)
    assert ahead.start(targets) is False
    assert ahead._helper is None
    with pytest.raises(ValueError, match=r"kernel kinds \['batch'\] are not allowed: use \('lean'"):
        K.compiling_ahead(["lean", "batch"])


def test_the_helper_refuses_an_unknown_kind():
    out = subprocess.run([sys.executable, "-m", "hunting.integrate.compile_kernels", "lean2"], capture_output=True,
                         text=True, timeout=120)
    assert out.returncode == 2 and "kernel kinds ['lean2'] are not allowed" in out.stderr


def test_the_kernel_lock_excludes_a_second_process_and_its_wait_is_bounded(tmp_path):
    """Kernel compiles hold an exclusive lock on the kernels' cache directory: while another
    process holds it a compile waits, and past the limit it goes on without it."""
    from hunting.integrate import _kernel as K
    disp = K._DISPATCHERS["lean"]
    path = os.path.join(disp._cache._cache_path, ahead.LOCK_NAME)
    holder = subprocess.Popen([sys.executable, "-c", "import fcntl, os, sys, time\n"
                               f"fd = os.open({path!r}, os.O_RDWR | os.O_CREAT)\n"
                               "fcntl.flock(fd, fcntl.LOCK_EX)\nprint('held', flush=True)\ntime.sleep(3)\n"],
                              stdout=subprocess.PIPE, text=True)
    try:
        assert holder.stdout.readline().strip() == "held"
        t0 = time.monotonic()
        with ahead.kernel_lock(disp, limit=0.3):
            waited = time.monotonic() - t0
        assert 0.3 <= waited < 2.0                       # gave up at the limit
        with ahead.kernel_lock(disp, limit=30.0):
            waited = time.monotonic() - t0
        assert 2.0 <= waited < 10.0                      # took it once the holder ended
    finally:
        holder.kill()
        holder.wait()


def test_a_stopped_helper_finishes_its_kernel_and_starts_no_other(tmp_path):
    """Closing the helper's standard input tells it to stop after the kernel it compiles (a
    kill between numba's index and data writes could leave an entry naming another file)."""
    env = dict(os.environ, NUMBA_CACHE_DIR=str(tmp_path / "numba"))
    proc = subprocess.Popen([sys.executable, "-m", "hunting.integrate.compile_kernels", "lean", "full"], env=env,
                            stdin=subprocess.PIPE, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    # stopped once the lean kernel is begun (a fixed wait let a fast machine finish it and begin
    # the full one first)
    assert proc.stdout.readline().strip() == "compiling lean"
    proc.stdin.close()
    assert proc.wait(timeout=300) == 0, proc.stderr.read()
    names = " ".join(os.listdir(tmp_path / "numba")) if (tmp_path / "numba").exists() else ""
    assert "integrate" in names                      # the lean kernel (begun at once) was finished
    kinds = subprocess.run([sys.executable, "-c", "from hunting.integrate import ahead, _kernel as K\n"
                            "print(ahead.cached(K._DISPATCHERS['lean'], K.KERNEL_SIG), "
                            "ahead.cached(K._DISPATCHERS['full'], K.KERNEL_SIG))"],
                           env=env, capture_output=True, text=True, timeout=120, check=True).stdout.split()
    assert kinds == ["True", "False"]                  # lean cached, full never begun


@pytest.mark.parametrize("preset, model, sets, lugre", [
    ("table8.1-lugre", None, [], True),
    ("table9.1", None, [], False),
    ("table8.1-lugre", None, [("model", "switch")], False),
    (None, "pid_lugre.json", [], True),
    (None, "belt.json", [], False),
    (None, "no_such_file.json", [], False),
])
def test_continue_compiles_the_full_kernel_ahead_for_a_lugre_contact(preset, model, sets, lugre):
    """A LuGre branch's sensitivities run Radau: `hunting continue` has the helper compile the
    full kernel after the lean and variational ones, read off the arguments without compiling
    the system (an unreadable file names none beyond those: the command reports it)."""
    import argparse
    from pathlib import Path

    from hunting.cli import continue_
    from hunting.cli.systems import names_lugre
    examples = Path(__file__).resolve().parents[1] / "examples"
    args = argparse.Namespace(preset=preset, model=str(examples / model) if model else None, set=sets)
    assert names_lugre(args) is lugre
    assert continue_.kernels(args) == (("variational", "full", "lean") if lugre else ("variational", "lean"))


def test_a_model_file_that_is_not_a_mapping_names_no_lugre(tmp_path):
    """A model file holding a JSON list: the kernel hint says no LuGre (the command itself then
    reports the file), never an unexpected error."""
    import argparse

    from hunting.cli.systems import names_lugre
    path = tmp_path / "list.json"
    path.write_text("[1, 2]")
    assert names_lugre(argparse.Namespace(preset=None, model=str(path), set=[])) is False
    path.write_text('{"friction": 3}')
    assert names_lugre(argparse.Namespace(preset=None, model=str(path), set=[])) is False
