"""The first run explains itself: in a terminal, `ropesim run` shows a spinner within half a second of starting,
says what compiles, that it happens once and where it is cached; the spinner leaves no trace, and nothing of
it appears when stderr is not a terminal or with --quiet.

The terminal is a real pseudo-terminal (``os.openpty``): the process sees a TTY on stdin, stdout and stderr,
as it does in a shell. What it wrote is replayed through a few lines of terminal emulation (carriage return,
line feed, cursor up, erase line: all the spinner uses) to get the screen a person would see at the end.
"""

from __future__ import annotations

import os
import re
import select
import signal
import subprocess
import sys
import tempfile
import time
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent
CSI = re.compile(r"\x1b\[([0-9;?]*)([A-Za-z])")
LIMIT = 0.5   # seconds from spawning the process to the first visible output (the requirement)


def visible(text: str) -> str:
    """What of ``text`` shows as characters: escape sequences and control characters removed."""
    return "".join(ch for ch in CSI.sub("", text) if ch.isprintable()).strip()


def screen(text: str) -> list[str]:
    """The lines left on a terminal after ``text`` (wide enough that nothing wraps)."""
    lines, row, col, i = [""], 0, 0, 0
    while i < len(text):
        m = CSI.match(text, i)
        if m:
            arg, cmd = m.groups()
            if cmd == "A":
                row = max(0, row - int(arg or 1))
            elif cmd == "K":
                lines[row] = "" if arg == "2" else lines[row][:col]
            i = m.end()
            continue
        ch, i = text[i], i + 1
        if ch == "\r":
            col = 0
        elif ch == "\n":
            row, col = row + 1, 0
            if row == len(lines):
                lines.append("")
        elif ch.isprintable():
            line = lines[row].ljust(col)
            lines[row] = line[:col] + ch + line[col + 1:]
            col += 1
    return [line.rstrip() for line in lines if line.strip()]


class Terminal:
    """``python -m ropesim ARGS`` on a pseudo-terminal; ``read_until`` collects what it writes, with times."""

    def __init__(self, args: list[str], cache: str, columns: int = 200):
        master, slave = os.openpty()
        env = {**os.environ, "NUMBA_CACHE_DIR": cache, "TERM": "xterm-256color", "COLUMNS": str(columns),
               "LINES": "50"}
        self.start = time.monotonic()
        self.proc = subprocess.Popen([sys.executable, "-m", "ropesim", *args], stdin=slave, stdout=slave,
                                     stderr=slave, cwd=ROOT, env=env, start_new_session=True)
        os.close(slave)
        self.master, self.text, self.first_visible = master, "", None

    def read_until(self, done, timeout: float) -> bool:
        """Read until ``done(text)`` holds or the process ends (True) or ``timeout`` seconds pass (False)."""
        end = time.monotonic() + timeout
        while time.monotonic() < end:
            ready, _, _ = select.select([self.master], [], [], 0.02)
            if ready:
                try:
                    chunk = os.read(self.master, 65536)
                except OSError:   # the process closed the terminal
                    chunk = b""
                if chunk:
                    now = time.monotonic()
                    self.text += chunk.decode("utf-8", errors="replace")
                    if self.first_visible is None and visible(self.text):
                        self.first_visible = now - self.start
                    if done(self.text):
                        return True
                    continue
                if self.proc.poll() is not None:
                    return True
            elif self.proc.poll() is not None and not select.select([self.master], [], [], 0)[0]:
                return True
        return False

    def finish(self, timeout: float) -> int:
        self.read_until(lambda text: False, timeout)
        return self.proc.wait(timeout=5)

    def kill(self) -> None:
        if self.proc.poll() is None:
            os.killpg(self.proc.pid, signal.SIGKILL)
        self.proc.wait(timeout=30)

    def close(self) -> None:
        self.kill()
        os.close(self.master)


def test_the_first_run_shows_progress_within_half_a_second_and_says_what_compiles(tmp_path):
    """A fresh, empty cache, so this run compiles. The first visible output must come within 0.5 s of
    spawning the process, Python's own start-up and imports included.

    A loaded machine can delay any process's start by itself (other jobs hold both cores), so the start is
    timed up to three times and the fastest counts: a start-up path that is too slow fails every time, a
    scheduling hiccup does not. The third try on would not be needed on an idle machine."""
    cache = tmp_path / "cache"
    args = ["run", "helicopter_mass", "--set", "integrator.t_end=0.2", "--out", str(tmp_path / "run")]
    latencies = []
    for attempt in range(3):
        term = Terminal(args, str(cache / str(attempt)))
        try:
            term.read_until(visible, 10)
            latencies.append(term.first_visible if term.first_visible is not None else float("inf"))
            if latencies[-1] > LIMIT:
                continue
            compiling = "Compiling the symplectic_euler kernel: once, then cached in " + str(cache / str(attempt))
            found = term.read_until(lambda text: compiling in CSI.sub("", text), 120)
            assert found, f"no compile message in {visible(term.text)[-500:]!r}"
            break
        finally:
            term.close()
    print(f"first visible output after {', '.join(f'{s:.3f}' for s in latencies)} s")
    assert min(latencies) <= LIMIT, f"first visible output after {latencies} s; must be within {LIMIT} s"


@pytest.fixture(scope="module")
def warm_cache():
    """This session's cache, holding the symplectic_euler kernel (compiled here unless an earlier test did)."""
    import ropesim

    ropesim.simulate(ropesim.load_scene("helicopter_mass", ["integrator.t_end=0.01"]))
    return os.environ["NUMBA_CACHE_DIR"]


def test_a_run_in_a_terminal_leaves_only_its_summary(tmp_path, warm_cache):
    term = Terminal(["run", "helicopter_mass", "--set", "integrator.t_end=0.2", "--out", str(tmp_path / "run")],
                    warm_cache)
    try:
        assert term.finish(120) == 0, visible(term.text)
    finally:
        term.close()
    # the spinner showed (which of its lines a refresh caught depends on the machine's load) ...
    assert re.search(r"Starting ropesim run|Preparing helicopter_mass|Running helicopter_mass", term.text)
    assert "Compiling" not in term.text                 # ... and nothing compiled: the kernel came from the cache
    lines = screen(term.text)
    assert lines[0] == "helicopter_mass: completed", lines  # ... and it left nothing behind
    assert not any("Preparing" in line or "Running" in line for line in lines)
    assert lines[-1].startswith("└")


def test_a_warning_and_an_error_print_cleanly_over_the_spinner(tmp_path, warm_cache):
    term = Terminal(["run", "helicopter_mass", "--set", "integrator.t_end=0.06", "--set", "integrator.dt=0.03",
                     "--out", str(tmp_path / "run")], warm_cache)
    try:
        assert term.finish(120) == 0, visible(term.text)
    finally:
        term.close()
    lines = screen(term.text)
    assert lines[0].startswith("ropesim: warning: built-in scene helicopter_mass: integrator.dt = 0.03 s is 95%")
    assert lines[1] == "helicopter_mass: completed", lines

    for args, first in [(["run", "no_such_scene"], "ropesim: no_such_scene: no such scene file or built-in scene"),
                        (["run", "helicopter_mass", "--bogus"], "Usage: python -m ropesim run [OPTIONS] [SCENE]")]:
        term = Terminal(args, warm_cache)
        try:
            assert term.finish(60) == 2
        finally:
            term.close()
        lines = screen(term.text)
        assert lines[0].startswith(first), lines
        assert not any("Starting" in line or "Preparing" in line for line in lines), lines


def test_quiet_in_a_terminal_prints_nothing(tmp_path, warm_cache):
    term = Terminal(["run", "helicopter_mass", "--set", "integrator.t_end=0.2", "--out", str(tmp_path / "run"),
                     "--quiet"], warm_cache)
    try:
        assert term.finish(120) == 0
    finally:
        term.close()
    assert visible(term.text) == ""


def _compile_something(name: str):
    """Compile a tiny function of ropesim's own, uncached: one ``numba:compile`` event, in a tenth of a second."""
    from numba import njit

    namespace: dict = {"__name__": "ropesim.test_probe"}
    exec(f"def {name}(x):\n    return x + 1\n", namespace)
    return njit(namespace[name])(1)


def test_no_spinner_and_no_listening_when_not_a_terminal_or_quiet(capfd):
    from ropesim.cli.status import Startup

    with Startup(True, "Preparing") as status:   # stderr is captured by pytest: not a terminal
        status.watch()
        assert _compile_something("probe_one") == 2
    with Startup(False, "Preparing") as quiet:   # --quiet
        quiet.watch()
        _compile_something("probe_two")
    out, err = capfd.readouterr()
    assert out == "" and err == ""
    assert status.compiles == 0 and quiet.compiles == 0   # disabled: not even listening


def test_the_spinner_line_names_what_compiles_and_where_it_is_cached(monkeypatch):
    from numba.core import event

    from ropesim.cli import status as module

    monkeypatch.setenv("NUMBA_CACHE_DIR", os.path.join(os.path.expanduser("~"), "kernels"))
    status = module.Startup(True, "Running helicopter_mass", kernel="the sdirk2 kernel")
    monkeypatch.setattr(status, "_show", lambda: None)   # the line alone, no terminal needed
    listener = None
    try:
        status.watch()
        listener = status._listener
        seen = []

        class Probe(event.Listener):
            def on_start(self, ev):
                seen.append(status.line().plain)

            def on_end(self, ev):
                pass

        probe = Probe()
        event.register("numba:compile", probe)
        try:
            _compile_something("probe_three")
        finally:
            event.unregister("numba:compile", probe)
    finally:
        status.close()
    assert listener is not None and status.compiles == 1 and status.functions == 1
    assert seen and seen[0].startswith("Compiling the sdirk2 kernel: once, then cached in ~/kernels  probe_three")
    assert status.line().plain == "Running helicopter_mass"   # back to the run once the compile ended
    assert module.describe("ropesim.integrate.splitting", "advance_splitting") == \
        "the symplectic_euler, verlet, yoshida4 and pefrl kernel"
    assert module.describe("ropesim.integrate.rk", "advance_rk") == "the rk4 kernel"
    assert module.describe("ropesim.model.terms", "accelerations") == "the force terms"
