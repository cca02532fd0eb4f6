"""Start-up: `ropesim --help`, a warm-cache `ropesim run scenarios/shooter_high.toml`, the first run's compile.

Every figure is the wall time of a whole new process (Python start-up included), median of --repeats runs,
with the CPU time (user + system) the process used beside it: on a shared machine the wall time of a short
process is stretched by whoever else is running, its CPU time much less.

- help: the `ropesim` console script next to this Python, `--help`.
- cold run: the shooter scene with an empty Numba cache (a fresh NUMBA_CACHE_DIR): everything compiles.
- warm run: the same again, with the cache the cold run left.

With --installed it also builds a throwaway virtual environment, installs the project into it normally
(not editable) with pip, makes the installed package read-only (a read-only bind mount when run as root,
else the write bits removed) and checks that the compile cache still works: the first run compiles and
writes its cache outside the package (see ropesim/io/numba_cache.py), the second loads it. NUMBA_CACHE_DIR is
unset there, as for a user; HOME is a fresh folder, and once a folder that cannot be written.

    python scripts/bench_startup.py [--repeats 7] [--installed]
"""

from __future__ import annotations

import argparse
import json
import os
import resource
import shutil
import subprocess
import sys
import tempfile
import time
from pathlib import Path

from rich.console import Console
from rich.table import Table

from benchlib import ROOT, load_note, median

SCENE = ROOT / "scenarios" / "shooter_high.toml"


def timed(cmd: list[str], env: dict | None = None, cwd: Path | None = None) -> tuple[float, float, str]:
    """(wall seconds, CPU seconds, stderr) of one run of ``cmd``; raises if it fails."""
    before = resource.getrusage(resource.RUSAGE_CHILDREN)
    start = time.perf_counter()
    proc = subprocess.run(cmd, env=env, cwd=cwd, stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True)
    wall = time.perf_counter() - start
    after = resource.getrusage(resource.RUSAGE_CHILDREN)
    if proc.returncode != 0:
        raise RuntimeError(f"{' '.join(map(str, cmd))} failed ({proc.returncode}): {proc.stderr.strip()}")
    cpu = (after.ru_utime - before.ru_utime) + (after.ru_stime - before.ru_stime)
    return wall, cpu, proc.stderr


def repeat(cmd, n, env=None, cwd=None) -> tuple[float, float]:
    runs = [timed(cmd, env, cwd) for _ in range(n)]
    return median([r[0] for r in runs]), median([r[1] for r in runs])


def console_script(bin_dir: Path) -> str:
    exe = bin_dir / ("ropesim.exe" if os.name == "nt" else "ropesim")
    return str(exe) if exe.exists() else shutil.which("ropesim") or "ropesim"


def compile_time(folder: Path) -> float:
    return json.loads((folder / "summary.json").read_text())["compile_time_s"]


def measure(ropesim: str, env: dict, work: Path, repeats: int) -> dict:
    """help, cold and warm figures for one installation, with ``env`` as the environment."""
    out = work / "run"
    run = [ropesim, "run", str(SCENE), "-o", str(out), "-q"]
    result = {"help": repeat([ropesim, "--help"], repeats, env, work)}
    wall, cpu, _ = timed(run, env, work)
    result["cold"] = (wall, cpu)
    result["cold_compile"] = compile_time(out)
    result["warm"] = repeat(run, repeats, env, work)
    result["warm_compile"] = compile_time(out)
    return result


def local(repeats: int) -> dict:
    """The project as installed here (editable), with a fresh Numba cache for the cold run."""
    with tempfile.TemporaryDirectory(prefix="ropesim-bench-") as tmp:
        env = dict(os.environ, NUMBA_CACHE_DIR=str(Path(tmp) / "numba"))
        return measure(console_script(Path(sys.executable).parent), env, Path(tmp), repeats)


class ReadOnly:
    """Make ``folder`` read-only: a read-only bind mount as root (root ignores write bits), else chmod."""

    def __init__(self, folder: Path):
        self.folder, self.mounted = folder, False

    def __enter__(self):
        if hasattr(os, "geteuid") and os.geteuid() == 0:
            f = str(self.folder)
            bound = subprocess.run(["mount", "--bind", f, f], capture_output=True).returncode == 0
            if bound and subprocess.run(["mount", "-o", "remount,bind,ro", f], capture_output=True).returncode == 0:
                self.mounted = True
                return self
            if bound:
                subprocess.run(["umount", f], capture_output=True)
            raise RuntimeError("running as root and cannot make a read-only bind mount: root ignores write bits, "
                               "so the read-only install cannot be tested here")
        for path in [self.folder, *self.folder.rglob("*")]:
            path.chmod(path.stat().st_mode & 0o555)
        return self

    def __exit__(self, *exc):
        if self.mounted:
            subprocess.run(["umount", str(self.folder)], check=True)
        else:
            for path in [self.folder, *self.folder.rglob("*")]:
                path.chmod(path.stat().st_mode | 0o200)


def installed(repeats: int, console: Console) -> dict:
    """A normal (non-editable) install into a throwaway venv whose package folder is read-only."""
    tmp = Path(tempfile.mkdtemp(prefix="ropesim-venv-"))
    try:
        console.print(f"building a throwaway venv in {tmp} and installing {ROOT} into it (non-editable) ...")
        subprocess.run([sys.executable, "-m", "venv", str(tmp / "venv")], check=True)
        py = tmp / "venv" / ("Scripts" if os.name == "nt" else "bin") / "python"
        subprocess.run([str(py), "-m", "pip", "install", "-q", str(ROOT)], check=True)
        # -I and a neutral cwd: the installed package, never a source tree the current folder would shadow it with
        where = "import ropesim, os; print(os.path.dirname(ropesim.__file__))"
        package = Path(subprocess.run([str(py), "-I", "-c", where], check=True, capture_output=True, text=True,
                                      cwd=tmp, env={"PATH": os.environ.get("PATH", "")}).stdout.strip())
        if not package.is_relative_to(tmp / "venv"):
            raise RuntimeError(f"the venv imports ropesim from {package}, not from its own site-packages: refusing "
                               f"to make that read-only")
        home = tmp / "home"
        home.mkdir()
        base = {k: os.environ[k] for k in ("PATH", "LANG", "TMPDIR") if k in os.environ}
        env = dict(base, HOME=str(home))
        ropesim = console_script(py.parent)
        with ReadOnly(package.parent):
            result = measure(ropesim, env, tmp, repeats)
            in_package = sorted(p.name for p in package.rglob("*.nbi"))
            cached = sorted(p.name for p in (home / ".cache").rglob("*.nbi"))
            # no writable home at all: the kernels go to the temporary directory
            (tmp / "tmpdir").mkdir()
            env_nohome = dict(base, HOME=str(package / "no-home"), TMPDIR=str(tmp / "tmpdir"))
            nohome = [timed([ropesim, "run", str(SCENE), "-o", str(tmp / "run2"), "-q"], env_nohome, tmp)[0]
                      for _ in range(2)]
        result.update(in_package=in_package, cached=cached, nohome=nohome)
        return result
    finally:
        shutil.rmtree(tmp, ignore_errors=True)


def add_rows(table: Table, label: str, r: dict) -> None:
    table.add_row(f"{label}: ropesim --help", f"{r['help'][0]:.2f} s", f"{r['help'][1]:.2f} s", "< 0.4 s", "")
    table.add_row(f"{label}: run shooter_high, warm cache", f"{r['warm'][0]:.2f} s", f"{r['warm'][1]:.2f} s",
                  "< 1.2 s", f"cache load {r['warm_compile']:.2f} s")
    table.add_row(f"{label}: run shooter_high, first run (compiles)", f"{r['cold'][0]:.2f} s",
                  f"{r['cold'][1]:.2f} s", "", f"kernel compile {r['cold_compile']:.2f} s")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--installed", action="store_true",
                        help="also test a normal install into a read-only location (builds a throwaway venv)")
    args = parser.parse_args()
    console = Console()
    table = Table(title=f"Start-up, whole process, median of {args.repeats}")
    for col in ("what", "wall", "CPU", "target", "note"):
        table.add_column(col, justify="left" if col in ("what", "note") else "right")
    add_rows(table, "editable install", local(args.repeats))
    if args.installed:
        r = installed(args.repeats, console)
        add_rows(table, "installed read-only", r)
        ok = not r["in_package"] and r["cached"]
        table.add_row("installed read-only: cache outside the package", "yes" if ok else "NO", "", "",
                      f"{len(r['cached'])} index files in ~/.cache/ropesim/numba, {len(r['in_package'])} in the "
                      f"package")
        table.add_row("installed read-only, no writable home: 1st, 2nd run", f"{r['nohome'][0]:.2f} s",
                      f"{r['nohome'][1]:.2f} s", "", "kernels cached in the temporary directory")
    console.print(table)
    console.print(load_note())


if __name__ == "__main__":
    main()
