"""The fault-injection campaign behind the totals in issue notes: every bad input of the fault tests' tables
and SIGKILLs at every checkpoint step, each as a command line in a process of its own.

    python tests/faults/campaign.py inputs [--src DIR] [--only ID,...]   # bad inputs, classified
    python tests/faults/campaign.py kills                                # kill, resume, compare

``inputs`` runs each case of ``test_bad_inputs.CASES`` and ``test_error_promise.CASES`` (and an env that
never terminates, which must run on after one warning line; and issue 30's, :func:`_lost_cases`) on a copy of its base run (the bases are
trained once, by the code under test), with a timeout and an address-space cap, and classifies it:
*clear* (exit 2, or 130 for an interrupt; exactly one ``shaped-es: error:`` line, which holds the table's
words; warnings are one line each), *internal* (exit 1 or a traceback), *silent* (exit 0), *hang* (the
timeout, or memory running out under the cap where the input asked for no memory: a blow-up), *noisy*
(exit 2 with other lines besides), *unnamed* (one line, without the table's words); and, independently,
*data changed* (a file of the run directory not byte-identical afterwards; error.log aside). ``--src``
runs another checkout's code (e.g. the main branch, for the numbers before a fix).

``kills`` SIGKILLs the trainer (``killer.py``) at each of the five steps of the checkpoint of generation 3
for vanilla, cmaes, shaped, shaped with ``checkpoint_every=3`` and ppo, during the first checkpoint
(vanilla), and during a resume (each method: train to 3, resume killed at generation 5's checkpoint, 6's
with ``checkpoint_every=3``);
each run is resumed and counts as *survived* when resume exits 0 and leaves a consistent directory
(no temporaries, half checkpoints or lock; 6 rows), *exact* when its rows equal the uninterrupted run's
(PPO restarts its training episodes on resume by design: exact up to the first checkpoint a resume
continued from).
"""

from __future__ import annotations

import argparse
import json
import os
import shutil
import sys
import tempfile
import time
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path[:0] = [str(HERE), str(HERE.parent)]

import fault_run  # noqa: E402
from fault_run import config, leftovers, run_cli, snapshot, write_config  # noqa: E402

TIMEOUT_S, MEMORY_GIB = 120, 6
WARNED = "warned: "  # a needle so marked: the command succeeds after one warning line holding the rest


def _use_src(src: str | None) -> None:
    """Make every command line (and this process) run the code under ``src``."""
    if src:
        fault_run.SRC = Path(src).resolve()
    sys.path.insert(0, str(fault_run.SRC))
    os.environ["PYTHONPATH"] = fault_run.env()["PYTHONPATH"]


def _cases() -> list[tuple[str, str | None, object, object, str]]:
    """(id, base, damage, command, needle) of the tables; test_bad_inputs' cases use its finished run."""
    import test_bad_inputs
    import test_error_promise

    endless = ("endless-env", None, test_bad_inputs.nothing, test_error_promise.train(env="fault_envs:Endless-v0"),
               WARNED + "cut at 10,000 steps")
    return [(c[0], "finished", *c[1:]) for c in test_bad_inputs.CASES] + list(test_error_promise.CASES) + \
        [endless] + _lost_cases()


BASES: dict[str, Path] = {}  # the bases of this campaign (a damage may copy from another run)


def _lost_cases() -> list[tuple[str, str | None, object, object, str]]:
    """Issue 30's cases: run directories not the run's own, failed resumes that changed files, checkpoints
    from elsewhere, env contract breaches, named pipes (and the test files that hold each)."""
    import numpy as np
    import test_env_contract
    import test_failed_resume
    from fault_run import newest, nothing, replace_with_file
    from test_bad_inputs import TRAIN, evaluate

    def resume5(run, tmp):
        return ["resume", str(run), "--generations", "5", "--quiet"]

    def other_seed(run, tmp):
        shutil.copy(newest(BASES["other"], ".npz"), newest(run, ".npz"))

    def edited(run, tmp):
        p = newest(run, ".npz")
        with np.load(p) as z:
            arrays = {k: z[k] * 2 if k == "policy/best" else z[k] for k in z.files}
        with open(p, "wb") as fh:
            np.savez(fh, **arrays)

    def fifo(rel):
        def f(run, tmp):
            (run / rel).unlink(missing_ok=True)
            os.mkfifo(run / rel)
        return f

    def user_folder(run, tmp):
        (tmp / "proj" / "notes").mkdir(parents=True)
        (tmp / "proj" / "notes" / ".draft.md.tmp").write_text("a user's draft")

    cases = [
        ("out-folder-of-other-files", None, user_folder,
         lambda run, tmp: ["train", "--env", "CartPole-v1", *TRAIN, "--out", str(tmp / "proj")],
         "holds no run but other files"),
        ("out-empty", None, nothing, lambda run, tmp: ["train", "--env", "CartPole-v1", *TRAIN, "--out", ""],
         "--out is empty"),
        ("resume-metrics-last-column-cut", "vanilla", test_failed_resume.cut_last_column, resume5,
         "lacks the columns"),
        ("resume-figures-is-a-file", "vanilla", replace_with_file("figures"), resume5, "is not a folder"),
        ("resume-tb-is-a-file", "tb", replace_with_file("tb"), resume5, "is not a folder"),
        ("ckpt-other-seeds-npz", "vanilla", other_seed, resume5, "holds the arrays of another run"),
        ("ckpt-older-generation-renamed", "vanilla", lambda run, tmp: shutil.copy(
            run / "checkpoints" / "gen_000003.npz", newest(run, ".npz")), resume5, "holds generation 3's arrays"),
        ("ckpt-arrays-edited", "vanilla", edited, resume5, "sha256 differs"),
        ("evaluate-other-seeds-npz", "vanilla", other_seed, evaluate(), "holds the arrays of another run"),
        ("fifo-metrics", "vanilla", fifo("metrics.csv"), resume5, "is a named pipe"),
        ("fifo-latest", "vanilla", fifo("checkpoints/latest.json"), resume5, "is a named pipe"),
        ("fifo-error-log", "vanilla", fifo("error.log"), resume5, "is a named pipe"),
        ("fifo-config", "vanilla", fifo("config.yaml"), resume5, "is a named pipe"),
        ("env-close-raises", None, nothing, test_error_promise_train("close_raises"), WARNED + "in close()"),
    ]
    cases += [(f"env-{cid}", None, nothing,
               (lambda argv: lambda run, tmp: ["train", *argv, "--out", str(tmp / "new")])(argv), needle)
              for cid, argv, needle in test_env_contract.CASES]
    return cases


def test_error_promise_train(fault):
    from test_env_contract import faulty

    return lambda run, tmp: ["train", *faulty(fault), "--out", str(tmp / "new")]


def _bases(root: Path) -> dict[str, Path]:
    import test_bad_inputs
    import test_error_promise

    out = {"finished": root / "finished"}
    res = run_cli("train", "--env", "CartPole-v1", *test_bad_inputs.TRAIN, "--out", out["finished"])
    assert res.returncode == 0, res.stderr
    out["vanilla"] = root / "vanilla"
    res = run_cli("train", *test_error_promise.VANILLA, "--out", out["vanilla"])
    assert res.returncode == 0, res.stderr
    out["shaped"] = root / "shaped"
    cfg = write_config(root / "shaped.yaml", config("shaped", generations=4, tensorboard=False))
    res = run_cli("train", "--config", cfg, "--out", out["shaped"], "--quiet")
    assert res.returncode == 0, res.stderr
    out["other"] = root / "other"  # the vanilla base's config with another seed (a checkpoint from elsewhere)
    res = run_cli("train", *test_error_promise.VANILLA, "--seed", "7", "--out", out["other"])
    assert res.returncode == 0, res.stderr
    out["tb"] = root / "tb"  # with TensorBoard events
    res = run_cli("train", *[x if x != "tensorboard=false" else "tensorboard=true" for x in
                             test_error_promise.VANILLA], "--out", out["tb"])
    assert res.returncode == 0, res.stderr
    BASES.update(out)
    return out


def classify(code: int | None, err: str, needle: str) -> str:
    lines = [ln for ln in err.splitlines() if ln.strip()]
    other = [ln for ln in lines if not ln.startswith("shaped-es: warning:")]
    if needle.startswith(WARNED) and code == 0:  # not an error: the run goes on after one warning line
        return "clear" if lines and all(ln.startswith("shaped-es: warning:") for ln in lines) and \
            needle[len(WARNED):] in lines[0] else "noisy"
    if code is None or (("out of memory" in err or "MemoryError" in err) and "GiB" not in needle):
        return "hang"
    if code == 1 or "Traceback" in err:
        return "internal"
    if code == 0:
        return "silent"
    if code == 130 and other == ["shaped-es: interrupted"]:
        return "clear"
    if code != 2 or len(other) != 1 or not other[0].startswith("shaped-es: error: "):
        return "noisy"
    return "clear" if needle in other[0] else "unnamed"


def inputs(only: set[str]) -> dict:
    import subprocess

    results = []
    with tempfile.TemporaryDirectory(prefix="campaign") as tmp_root:
        bases = _bases(Path(tmp_root))
        for cid, base, damage, command, needle in _cases():
            if only and cid not in only:
                continue
            tmp = Path(tempfile.mkdtemp(dir=tmp_root))
            (tmp / "mods").mkdir()
            run = tmp / "run"
            if base:
                shutil.copytree(bases[base], run)
            damage(run, tmp)
            before = snapshot(run)
            argv = command(run, tmp)
            t0 = time.time()
            try:
                res = run_cli(*argv, timeout=TIMEOUT_S, cwd=tmp / "mods", memory_gib=MEMORY_GIB)
                code, err = res.returncode, res.stderr
            except subprocess.TimeoutExpired as exc:
                code, err = None, exc.stderr.decode() if isinstance(exc.stderr, bytes) else (exc.stderr or "")
            outcome = classify(code, err, needle)
            changed = snapshot(run) != before
            results.append({"id": cid, "outcome": outcome, "data_changed": changed, "exit": code,
                            "seconds": round(time.time() - t0, 1), "stderr": err.strip()[-300:]})
            print(f"{cid:32s} {outcome:9s} exit={code} changed={changed}", flush=True)
    totals = {"tried": len(results)} | {k: sum(r["outcome"] == k for r in results) for k in
                                        ("clear", "internal", "silent", "hang", "noisy", "unnamed")}
    totals["data_changed"] = sum(r["data_changed"] for r in results)
    return {"totals": totals, "cases": results}


def _kill_resume(method: str, point: str, gen: int, tmp: Path, ref: list[dict], during_resume: bool) -> dict:
    from helpers import strip_time

    from shaped_es.rundir.store import RunStore

    cfg = write_config(tmp / "cfg.yaml", config(method))
    run = tmp / "run"
    killer = [str(HERE / "killer.py"), point, str(gen)]
    if during_resume:  # train to 3 generations, then a resume to 6 killed at generation `gen`'s checkpoint
        assert run_cli("train", "--config", cfg, "--generations", 3, "--out", run, "--quiet").returncode == 0
        killed = run_cli("resume", run, "--generations", 6, "--quiet", prefix=killer)
    else:
        killed = run_cli("train", "--config", cfg, "--out", run, "--quiet", prefix=killer)
    injected = killed.returncode == -9
    res = run_cli("resume", run, "--generations", 6, "--quiet")
    rows = RunStore(run).read_metrics() if res.returncode == 0 else []
    survived = res.returncode == 0 and leftovers(run) == [] and len(rows) == 6
    if method == "ppo":  # up to the first checkpoint a resume continued from (generation 3 or gen - 1)
        upto = 3 if during_resume else gen - 1
        exact = survived and strip_time(rows)[:upto] == strip_time(ref)[:upto]
    else:
        exact = survived and strip_time(rows) == strip_time(ref)
    return {"injected": injected, "survived": survived, "exact": exact, "stderr": res.stderr.strip()[-300:]}


def kills(only: set[str]) -> dict:
    from killer import POINTS

    from shaped_es.rundir.store import RunStore

    methods = ("vanilla", "cmaes", "shaped", "shaped_ce3", "ppo")
    plan = [(m, p, 3, False) for m in methods for p in POINTS]
    plan += [("vanilla", p, 1, False) for p in ("npz_tmp", "json_rename", "metrics_append")]
    plan += [(m, "json_rename", 6 if m == "shaped_ce3" else 5, True) for m in methods]  # ce3: 3, 6
    name = lambda m, p, g, r: f"{m}-{p}-gen{g}" + ("-during-resume" if r else "")  # noqa: E731
    plan = [x for x in plan if not only or name(*x) in only]
    results = []
    with tempfile.TemporaryDirectory(prefix="kills") as tmp_root:
        refs = {}
        for m in sorted({x[0] for x in plan}):
            d = Path(tmp_root) / f"ref_{m}"
            d.mkdir()
            cfg = write_config(d / "cfg.yaml", config(m))
            assert run_cli("train", "--config", cfg, "--out", d / "run", "--quiet").returncode == 0
            refs[m] = RunStore(d / "run").read_metrics()
        for m, p, g, during_resume in plan:
            tmp = Path(tempfile.mkdtemp(dir=tmp_root))
            r = _kill_resume(m, p, g, tmp, refs[m], during_resume)
            r["case"] = name(m, p, g, during_resume)
            results.append(r)
            print(f"{r['case']:40s} injected={r['injected']} survived={r['survived']} exact={r['exact']}",
                  flush=True)
    totals = {k: sum(r[k] for r in results) for k in ("injected", "survived", "exact")}
    return {"totals": {"planned": len(results), **totals}, "cases": results}


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("what", choices=("inputs", "kills"))
    ap.add_argument("--src", help="run this checkout's src/ instead of this tree's")
    ap.add_argument("--only", default="", help="comma-separated case ids")
    ap.add_argument("--json", help="write the results here")
    a = ap.parse_args()
    _use_src(a.src)
    only = {x for x in a.only.split(",") if x}
    out = inputs(only) if a.what == "inputs" else kills(only)
    print(json.dumps(out["totals"]))
    if a.json:
        Path(a.json).write_text(json.dumps(out, indent=1))


if __name__ == "__main__":
    main()
