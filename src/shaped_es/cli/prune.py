"""``shaped-es prune DIR...``: free the disk of finished runs (``rundir/prune.py`` decides what goes): one
line per run saying what was freed (or would be, ``--dry-run``) or why it was skipped, then the total. A
benchmark folder stands for the runs under its ``runs/`` (as for ``report``), a suite folder for every
task's; anything else that is not a run directory is refused before anything is deleted."""

from __future__ import annotations

import argparse
from pathlib import Path

from shaped_es.cli.results import expand_run_dirs


def add_prune_parser(sub) -> argparse.ArgumentParser:
    p = sub.add_parser("prune", help="free a finished run's disk: delete what only an exact resume reads",
                       description="Delete, in each finished run, what only an exact resume reads: the "
                       "mphi_data* folders, trajectories/ and the checkpoints older than the newest. "
                       "evaluate, render, report and load_policy keep working; resume refuses the run "
                       "afterwards (a run that lost only older checkpoints stays resumable).")
    p.add_argument("run_dirs", nargs="+", metavar="DIR",
                   help="run directories, benchmark directories (their runs/) or suite directories (each "
                   "task's runs/)")
    p.add_argument("--dry-run", action="store_true", help="print what would be deleted; delete nothing")
    p.add_argument("--force", action="store_true",
                   help="prune unfinished runs too (they then cannot be resumed); a run another process is "
                   "writing is never pruned (default: finished runs only)")
    p.set_defaults(fn=cmd_prune)
    return p


def runs_under(paths: list[str]) -> list[Path]:
    """The run directories ``paths`` name (a benchmark folder: its ``runs/``; a suite folder, one with
    ``suite.yaml``: each task's ``runs/``), each once; ``StoreError`` (one line) for a path that is none
    of these, or a run directory whose config cannot be read, before anything is pruned."""
    from shaped_es.rundir.store import RunStore, StoreError

    out: list[Path] = []
    for p in map(Path, paths):
        if (p / "config.yaml").exists():
            RunStore(p).read_config()  # a config that is no run's: refused in its own one line
            out.append(p)
        elif (p / "runs").is_dir():
            out += expand_run_dirs([str(p)])
        elif (p / "suite.yaml").is_file():
            tasks = sorted(str(d) for d in p.iterdir() if d.is_dir() and (d / "runs").is_dir())
            out += expand_run_dirs(tasks)
        elif not p.exists():
            raise StoreError(f"{p} does not exist: nothing pruned")
        else:
            raise StoreError(f"{p} is not a run directory (no config.yaml), nor a benchmark (runs/) or suite "
                             f"(suite.yaml) folder: nothing pruned")
    seen: dict[Path, Path] = {}
    for p in out:
        seen.setdefault(p.resolve(), p)
    return list(seen.values())


def _mb(nbytes: int) -> str:
    return f"{nbytes / 1e6:.1f} MB"


def cmd_prune(a: argparse.Namespace) -> int:
    from shaped_es.rundir.prune import prune_run
    from shaped_es.run_loop import run_finished

    runs = runs_under(a.run_dirs)
    total, pruned = 0, 0
    for root in runs:
        res = prune_run(root, run_finished, force=a.force, dry_run=a.dry_run)
        notes = "".join(f"; {n}" for n in res.notes)
        what = f" ({', '.join(res.parts)})" if res.parts else ""
        if res.status == "skipped":
            print(f"skipped {root}: {res.why}", flush=True)
        elif res.status == "nothing":
            print(f"{root}: nothing freed{notes}", flush=True)
        else:
            done = "would prune" if a.dry_run else "pruned"
            print(f"{done} {root}: {_mb(res.nbytes)}{'' if a.dry_run else ' freed'}{what}{notes}", flush=True)
            total += res.nbytes
            pruned += 1
    verb = "would be freed" if a.dry_run else "freed"
    print(f"total: {_mb(total)} {verb} from {pruned} of {len(runs)} run{'s' * (len(runs) != 1)}"
          f"{' (--dry-run: nothing deleted)' if a.dry_run else ''}")
    return 0
