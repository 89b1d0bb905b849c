"""Time `run_verification` (default settings, the book's scenarios in the procedure MC) and its
parts.

python benchmarks/bench_verify.py [--trials T] [--repeat R]
python benchmarks/bench_verify.py --jobs     # CPU seconds of each procedure-MC job, serially
python benchmarks/bench_verify.py --phases   # and each job's CPU split into its parts
python benchmarks/bench_verify.py --timeline # `verify --json -q` as the CLI runs it, on a clock
python benchmarks/bench_verify.py --variance [--trials T]   # regression control variates, setup

``--jobs`` runs the default ``verify``'s procedure-MC jobs one after another in this process
(one BLAS thread, as in a worker) and prints each job's CPU seconds (user + system), their sum
and the linear rows' CPU: on two cores the wall of ``verify`` cannot go below about half their
total plus the start-up (imports, loading the scenarios).

``--phases`` runs the same jobs and splits each job's CPU (``time.process_time``) into what a
job pays once — the run preparation (``ProcedureRun.prepared``, twice), the error-free run, the
fields' set-up, the linearisation's discovery run (1 trial) and its designed run (1 + 2K
trials) — and what grows with its trials: the noisy trials' procedure, the control variate
(``control_variate.per_trial_controlled``) and the rest (the fields δp, the levelling and the
decomposition), as a Markdown table. On the ideal instrument the designed run goes in one run
with the first chunk of trials (``procedure_run.mean_squares``): its time is then under
"trials", and "design" holds only the runs with instrument errors.

``--timeline`` runs ``stereoplotter verify --json -q`` in this process exactly as the command
line does (the same worker processes) and prints when each part of the main process ended and
when each procedure-MC job started and ended in which worker, seconds from this process's start
(with its CPU seconds): where the two cores sit idle, and the critical path.

``--variance`` runs the 60 % setup job (its first T trials, default 16 000) and asks how much
a richer control variate would narrow each reading's CI: the per-trial variance of today's
estimator (mean_p v² − L + E[L]) against a fitted control coefficient of L, and a regression on
L and the active inputs' draws u (linear; + u² − 1; + the products uₖuₗ: every control of
known mean 0, the draws being independent standard normals), in-sample. The variance ratio is
the ratio of trials for the same CI. Nothing of ``verify`` changes.
"""

import argparse
import os
import time

import numpy as np
from threadpoolctl import threadpool_limits

from stereoplotter.io.book_setting import book_instrument, book_scenarios
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification import table as v


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--trials", type=int, default=60000)
    ap.add_argument("--repeat", type=int, default=3)
    ap.add_argument("--jobs", action="store_true", help="CPU seconds of each procedure-MC job")
    ap.add_argument("--phases", action="store_true", help="each job's CPU split into its parts")
    ap.add_argument("--timeline", action="store_true", help="verify --json -q on a clock")
    ap.add_argument("--variance", action="store_true", help="richer control variates, setup")
    a = ap.parse_args()
    if a.variance:
        variance(16000 if a.trials == 60000 else a.trials)
        return
    if a.timeline:
        timeline()
        return
    if a.phases:
        jobs_phases()
        return
    if a.jobs:
        jobs_cpu(a.trials)
        return
    scenarios, spec = book_scenarios(), book_instrument()
    best = min(
        _timed(
            lambda: v.run_verification(
                trials=a.trials, procedure_scenarios=scenarios, instrument=spec
            )
        )
        for _ in range(a.repeat)
    )
    specs = v.row_entries(dict(v.BOOK))
    t_spec = _timed(lambda: v.row_entries(dict(v.BOOK)))
    t_cov = _timed(lambda: [mc.covariance_rms(e.model) for e in specs])
    rng = np.random.default_rng(0)
    t_mc = _timed(lambda: [mc.mc_rms(e.model, a.trials, rng) for e in specs])
    print(f"cpu_count={os.cpu_count()} numpy={np.__version__} rows={len(specs)} trials={a.trials}")
    print(f"run_verification best of {a.repeat}: {best:.2f} s")
    print(
        f"  row models + formulas {t_spec:.3f} s, covariance {t_cov:.3f} s, linear MC {t_mc:.2f} s"
    )


def jobs_cpu(trials):
    """Each procedure-MC job of the default ``verify`` and the linear rows, CPU seconds."""
    pending = v.start_procedure_mc(
        None, 20240601, book_scenarios(), instrument=book_instrument(), workers=1
    )
    total = 0.0
    with threadpool_limits(limits=1, user_api="blas"):
        for i in pending.order:
            job = pending.jobs[i]
            cpu = _cpu(lambda job=job: v.run_procedure_job(job))
            total += cpu
            print(f"{cpu:6.2f} s  {' '.join(pending.keys[i][0])}  trials {job.trials}")
        entries = v.row_entries(dict(v.BOOK))
        rows = _cpu(lambda: [_linear(e, trials) for e in entries])
    print(f"procedure MC jobs {total:.2f} s CPU, linear rows {rows:.2f} s CPU")
    half = (total + rows) / 2
    print(f"half of their sum (the wall floor on two cores, start-up aside): {half:.2f} s")


#: The parts of a job in :func:`jobs_phases`, in the order of the table's columns.
PHASES = (
    "prepare",
    "zero run",
    "field set-up",
    "discovery",
    "design",
    "trials",
    "control variate",
)


def jobs_phases():
    """Each procedure-MC job of the default ``verify`` with its CPU split into :data:`PHASES`
    (each part wrapped with a CPU clock here) and the rest, seconds."""
    from stereoplotter.verification import control_variate as cv
    from stereoplotter.verification import procedure_run as pr

    spent = dict.fromkeys(PHASES, 0.0)

    def clocked(fn, part):
        def run(*args, **kwargs):
            t = time.process_time()
            try:
                return fn(*args, **kwargs)
            finally:
                spent[part(args, kwargs) if callable(part) else part] += time.process_time() - t

        return run

    def run_part(args, kwargs):
        noise = type(kwargs.get("noise")).__name__
        if args[2] is None:
            return "zero run"
        if noise == "DesignNoise":
            return "discovery" if args[2] == 1 else "design"
        return "trials"

    pr.run_trials_chunk = clocked(pr.run_trials_chunk, run_part)
    cv.per_trial_controlled = clocked(cv.per_trial_controlled, "control variate")
    pr._setup_fields = clocked(pr._setup_fields, "field set-up")
    pr._conventional_fields = clocked(pr._conventional_fields, "field set-up")
    pr.ProcedureRun.prepared = clocked(pr.ProcedureRun.prepared, "prepare")
    pending = v.start_procedure_mc(
        None, 20240601, book_scenarios(), instrument=book_instrument(), workers=1
    )
    totals = dict.fromkeys((*PHASES, "rest", "CPU"), 0.0)
    print("| job | trials | CPU | " + " | ".join(PHASES) + " | rest |")
    print("|---|---:|---:|" + "---:|" * (len(PHASES) + 1))
    with threadpool_limits(limits=1, user_api="blas"):
        for i in pending.order:
            job = pending.jobs[i]
            for k in spent:
                spent[k] = 0.0
            t = time.process_time()
            v.run_procedure_job(job)
            cpu = time.process_time() - t
            rest = cpu - sum(spent.values())
            for k in PHASES:
                totals[k] += spent[k]
            totals["rest"] += rest
            totals["CPU"] += cpu
            parts = " | ".join(f"{spent[k]:.3f}" for k in PHASES)
            name = " ".join(pending.keys[i][0])
            print(f"| {name} | {sum(job.trials.values())} | {cpu:.3f} | {parts} | {rest:.3f} |")
    parts = " | ".join(f"{totals[k]:.2f}" for k in (*PHASES, "rest"))
    print(f"| **all** | | **{totals['CPU']:.2f}** | {parts} |")


def _since_start():
    """Seconds since this process (the parent of the workers) started: Linux's boot-time clock
    against the start in ``/proc/self/stat`` (clock ticks, 10 ms)."""
    return time.clock_gettime(time.CLOCK_BOOTTIME) - _START


def _process_start():
    with open("/proc/self/stat") as f:
        fields = f.read().rpartition(")")[2].split()
    return int(fields[19]) / os.sysconf("SC_CLK_TCK")  # field 22, starttime


_START = _process_start()
#: Where the forked workers of :func:`timeline` write one line a job (set by it).
_JOB_LOG = []


def _timed_job(job, run=v.run_procedure_job):
    """:func:`~stereoplotter.verification.table.run_procedure_job` with its start, end
    (:func:`_since_start`) and CPU seconds appended to the file :data:`_JOB_LOG` names."""
    start, cpu = _since_start(), time.process_time()
    out = run(job)
    name = " ".join(job.configs) + (" instrument" if job.instrument_errors else "")
    line = (
        f"{os.getpid()}\t{name}\t{start:.2f}\t{_since_start():.2f}\t{time.process_time() - cpu:.2f}"
    )
    with open(_JOB_LOG[0], "a") as f:
        f.write(line + "\n")
    return out


def timeline():
    """``verify --json -q`` as the CLI runs it, with the end of each part of the main process
    and the start and end of each procedure-MC job in its worker (seconds since this process
    started, CPU seconds of the main process so far or of the job), as a Markdown table."""
    import contextlib
    import io
    import sys
    import tempfile

    import stereoplotter.commands.verification as command
    from stereoplotter.cli import main as cli

    log = []

    def mark(what):
        log.append(("main", what, "", f"{_since_start():.2f}", f"{time.process_time():.2f}"))

    mark("imports (this script's)")

    def wrapped(name):
        fn = getattr(command, name)

        def run(*args, **kwargs):
            out = fn(*args, **kwargs)
            mark(name)
            return out

        setattr(command, name, run)

    for name in ("start_book_procedure_mc", "verify", "attach_procedure_mc", "json_text"):
        wrapped(name)
    v.run_procedure_job = _timed_job  # looked up by the workers' job function when it runs
    sys.argv = ["stereoplotter", "verify", "--json", "-q"]
    with tempfile.TemporaryDirectory() as tmp:
        _JOB_LOG.append(os.path.join(tmp, "jobs.tsv"))
        with contextlib.redirect_stdout(io.StringIO()), contextlib.suppress(SystemExit):
            cli()
        mark("done")
        with open(_JOB_LOG[0]) as f:
            jobs = [line.rstrip("\n").split("\t") for line in f]
    jobs.sort(key=lambda j: float(j[3]))
    rows = log[:-3] + [(f"worker {pid}", *rest) for pid, *rest in jobs] + log[-3:]
    print("| process | part | start | end | CPU |")
    print("|---|---|---:|---:|---:|")
    for row in rows:
        print("| " + " | ".join(row) + " |")


def variance(trials):
    """The variance of today's controlled per-trial values of the 60 % setup job's readings
    against richer control variates (module docstring), printed per reading."""
    from stereoplotter.verification import control_variate as cv

    caught = {}
    controlled = cv.per_trial_controlled

    def catch(fields, lin, noise, injected, model, on=None):
        out = controlled(fields, lin, noise, injected, model, on)
        n = next(iter(fields.values())).shape[0]
        for name, field in fields.items():
            active = np.flatnonzero(np.any(lin.gradient[name] != 0.0, axis=1))
            u = np.zeros((len(active), n))
            for row, j in enumerate(active):
                kind, _, key = lin.inputs[j].partition(":")
                z = noise.z.get(key) if kind == "noise" else None
                if z is not None:
                    u[row] = z
            plain = np.mean(np.asarray(field) ** 2, axis=-1)
            caught.setdefault(name, []).append((plain, out[name], u))
        return out

    cv.per_trial_controlled = catch
    pending = v.start_procedure_mc(
        None, 20240601, book_scenarios(), instrument=book_instrument(), workers=1
    )
    job = next(j for j in pending.jobs if j.configs == ("setup",) and not j.instrument_errors)
    job = type(job)(**{**job.__dict__, "trials": {k: trials for k in job.trials}})
    with threadpool_limits(limits=1, user_api="blas"):
        v.run_procedure_job(job)
    print(f"60 % setup, {trials} trials: variance / today's controlled (= trials for one CI)")
    print("| reading | active inputs | plain | fitted β | + u | + u² − 1 | + uₖuₗ |")
    print("|---|---:|---:|---:|---:|---:|---:|")
    for name, parts in caught.items():
        y, c, u = (np.concatenate([p[i] for p in parts], axis=-1) for i in range(3))
        lin = y - c  # L − E[L]
        beta = np.cov(y, lin)[0, 1] / np.var(lin)
        pairs = np.triu_indices(len(u), 1)
        sets = (u.T, np.column_stack([u.T, (u**2 - 1).T]))
        sets += (np.column_stack([sets[1], (u[pairs[0]] * u[pairs[1]]).T]),)
        ratios = []
        for x in sets:
            x = np.column_stack([x, lin])
            x = x - x.mean(0)
            coef, *_ = np.linalg.lstsq(x, y - y.mean(), rcond=None)
            ratios.append(np.var(y - x @ coef) / np.var(c))
        cells = " | ".join(f"{r:.3f}" for r in ratios)
        print(
            f"| {name} | {len(u)} | {np.var(y) / np.var(c):.2f} | "
            f"{np.var(y - beta * lin) / np.var(c):.3f} | {cells} |"
        )


def _linear(entry, trials):
    """The linear MC of a row as the table runs it (a squared statistic: 4 × the trials)."""
    n = 4 * trials if entry.squared else trials
    return mc.mc_rms(entry.model, n, v.row_stream(20240601, entry))


def _cpu(fn):
    t0 = os.times()
    fn()
    t1 = os.times()
    return (t1.user - t0.user) + (t1.system - t0.system)


def _timed(fn):
    t0 = time.perf_counter()
    fn()
    return time.perf_counter() - t0


if __name__ == "__main__":
    main()
