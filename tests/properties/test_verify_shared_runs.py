"""Issue 26 (3): the work ``verify`` shares — the conventional configurations of one slot in one
run with a block of trials per judgment source, and the linear Monte Carlo's per-trial mean
square as a quadratic form of the draws — gives what the separate computations give."""

from __future__ import annotations

import math

import numpy as np
import pytest

from stereoplotter.io.book_setting import book_instrument, book_scenarios
from stereoplotter.verification import control_variate as cvar
from stereoplotter.verification import linear_mc as mc
from stereoplotter.verification import procedure_mc as pm
from stereoplotter.verification import table as v


def _field_by_drawing(model, trials, rng, chunk=4000):
    """The linear MC's per-trial mean squares drawn as a field (the pre-issue-26 way): the
    same draws in the same order, the field built from them and squared point by point."""
    P = model.G.shape[1]
    out = np.empty(trials)
    for start in range(0, trials, chunk):
        t = min(chunk, trials - start)
        e = rng.standard_normal((t, model.M.shape[1])) @ model.M.T
        field = e @ model.G
        if model.Gc is not None:
            fc = e @ model.Gc
            if model.sigma_control:
                fc = fc + model.sigma_control * rng.standard_normal((t, fc.shape[1]))
            field -= fc @ model.P_fit.T
        if model.sigma_white:
            field += model.sigma_white * rng.standard_normal((t, P))
        out[start : start + t] = np.mean(field**2, axis=1)
    return out


def test_linear_mc_quadratic_form_is_the_drawn_field():
    """Every row model of the table (with and without control noise, white noise, a plane
    removed): the per-trial mean squares of :func:`mc_rms` equal the field drawn and squared
    point by point, trial by trial, to rounding (1e-12 of the mean: a trial whose plane removal
    cancels its field keeps the absolute rounding of the mean square)."""
    specs = v.row_entries(dict(v.BOOK))
    kinds = set()
    for e in specs:
        m = e.model
        kinds.add((m.Gc is not None, bool(m.sigma_control), bool(m.sigma_white)))
        _, _, got = mc.mc_rms(m, 4500, np.random.default_rng(3))
        want = _field_by_drawing(m, 4500, np.random.default_rng(3))
        np.testing.assert_allclose(got, want, rtol=1e-12, atol=1e-12 * float(np.mean(want)))
    assert {(False, False, False), (True, False, False), (True, True, False)} <= kinds
    assert (True, True, True) in kinds


@pytest.fixture(scope="module")
def book80():
    return book_scenarios()["80"], book_instrument()


def test_shared_conventional_run_is_each_configuration_on_its_trials(book80):
    """One run with blocks ``both`` (trials 0–5), ``y_parallax`` (6–11), ``stereo`` (12–17)
    against three runs of :func:`_run` with only that source on, over trials 0 … last of the
    same seed: each block's per-trial mean squares are the separate run's on the same trials
    (exactly: the masked acts draw 0, as a σ = 0 act does); its controlled estimate equal to
    1e-4, far inside its CI (the linearisation is the same, but an act that only some trials of
    a chunk make is drawn for the whole chunk and counts in L of every trial of it: a trial's L
    depends on its chunk-mates; measured 1.2e-5 relative here)."""
    sc, spec = book80
    blocks = {"both": 6, "y_parallax": 6, "stereo": 6}
    merged = pm.conventional_sources_mc(sc, spec=spec, trials=blocks, seed=5, passes=3)
    g = pm.scenario_geometry(sc, spec)
    first = 0
    for source, n in blocks.items():
        o = pm.ProcedureOptions(passes=3, sources=source)
        plain, ctl, _, units = pm.run_configuration(
            sc, spec, "conventional", first + n, 5, o, g, spec.decentration_linkage
        )
        r = merged[source]
        assert r["sources"] == source and r["first_trial"] == first and r["trials"] == n
        sep = np.sqrt(plain["plane"][first:]) / units["plane"]
        np.testing.assert_array_equal(r["per_trial"], sep)
        value = math.sqrt(np.mean(ctl["plane"][first:])) / units["plane"]
        assert r["coefficient"] == pytest.approx(value, rel=1e-4)
        for k in ("slip", "book"):
            cf, _ = pm.rms_ci(ctl[k][first:], units[k])
            assert r["by_datum"][k][0] == pytest.approx(cf, rel=1e-4)
        first += n


def test_source_noise_masks_only_its_sources():
    """:class:`SourceNoise` draws 0 for a masked prefix on the masked trials and the keyed draw
    elsewhere; other keys are untouched; the recorded z are the masked ones."""
    off = {"q/": np.array([True, False, True])}
    noise = cvar.SourceNoise(11, 3, 4, off)
    plain = cvar.RecordingNoise(11, 3, 4)
    q, s = noise.normal("q/1", 0.5), noise.normal("stereo/1", 0.5)
    q0, s0 = plain.normal("q/1", 0.5), plain.normal("stereo/1", 0.5)
    np.testing.assert_array_equal(q, np.where(off["q/"], 0.0, q0))
    np.testing.assert_array_equal(s, s0)
    np.testing.assert_array_equal(noise.z["q/1"], q / 0.5)


def test_designed_run_beside_a_chunk_leaves_each_trial_its_own_state(book80):
    """The linearisation's designed run in one run with a chunk of trials
    (:class:`StackedNoise`, as ``procedure_run.mean_squares`` runs them on the ideal
    instrument): every trial's instrument state is bit for bit the one of its part run alone —
    the designed trials, and trials 7 … 16 of the seed — and the chunk's recorded draws are
    those of its own run: the procedure treats every trial alone."""
    from dataclasses import replace

    from stereoplotter.procedure.operator import OperatorModel
    from stereoplotter.procedure.simulate import prepare_run, run_trials_chunk
    from stereoplotter.verification import decomposition as dc

    sc, spec = book80
    op = replace(OperatorModel().zero(), monocular_sigma_mm=0.01)
    prep = prepare_run(sc, spec, "setup", "zero", 5, operator=op, ideal_mechanics=True)

    def run(injected, noise, trials):
        return run_trials_chunk(
            prep, 0, trials, evaluate=False, transcript=False, injected=injected, noise=noise
        )

    design = cvar.design(lambda inj, noise, n: (run(inj, noise, n), {})[1], prep.model)
    assert design.trials > 1
    first, t = 7, 10
    injected = prep.model.draw_keyed(prep.seed, first, first + t)
    alone_noise = cvar.RecordingNoise(prep.seed, t, first)
    alone = run_trials_chunk(
        prep, first, t, evaluate=False, transcript=False, injected=injected, noise=alone_noise
    )
    alone_design = run(design.injected, design.noise(), design.trials)
    recorded = cvar.RecordingNoise(prep.seed, t, first)
    d = design.trials
    both_injected = {
        k: np.concatenate([np.broadcast_to(np.asarray(design.injected[k], float), (d,)), v])
        for k, v in injected.items()
    }
    both = run_trials_chunk(
        prep,
        first,
        d + t,
        evaluate=False,
        transcript=False,
        injected=both_injected,
        noise=cvar.StackedNoise(design.noise(), recorded),
    )

    def state(result):
        units = result.instrument.state()["units"]
        objects = {"setting": result.instrument.setting, **units}
        return {key: np.asarray(getattr(objects[key[0]], key[1]), float) for key in dc.STATE}

    s_both, s_design, s_alone = state(both), state(alone_design), state(alone)
    for key in dc.STATE:
        np.testing.assert_array_equal(np.broadcast_to(s_both[key], (d + t,))[:d], s_design[key])
        np.testing.assert_array_equal(np.broadcast_to(s_both[key], (d + t,))[d:], s_alone[key])
    assert recorded.z.keys() == alone_noise.z.keys()
    for key, z in alone_noise.z.items():
        np.testing.assert_array_equal(recorded.z[key], z)
