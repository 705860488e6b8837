"""The Python package against the command line it wraps: the same forces as
`friction simulate`, the same servo figures as `friction servo`, parameter
errors that name the parameter, and the observer, compensator and
identification on known cases."""

import csv
import pathlib
import subprocess

import numpy as np
import pytest

import friction

ROOT = pathlib.Path(__file__).resolve().parents[2]
PARAMS = ROOT / "params"


def signal(n=4000, h=1e-4):
    t = np.arange(n) * h
    v = 2e-3 * np.sin(2 * np.pi * 5 * t) + 3e-4 * np.sin(2 * np.pi * 0.7 * t)
    return t, v


def cli_simulate(cli, tmp_path, params, t, v, scalar="f64"):
    inp = tmp_path / "in.csv"
    out = tmp_path / f"out-{scalar}.csv"
    with open(inp, "w") as f:
        f.write("t,v\n")
        for a, b in zip(t, v):
            f.write(f"{float(a)!r},{float(b)!r}\n")
    subprocess.run(
        [str(cli), "simulate", "--params", str(params), "--input", str(inp),
         "--output", str(out), "--scalar", scalar],
        check=True, capture_output=True,
    )
    with open(out) as f:
        return [row["f"] for row in csv.DictReader(f)]


@pytest.mark.parametrize("name,scalar", [
    ("canudas1995", "f64"), ("canudas1995", "f32"), ("canudas1995", "fixed"),
    ("gms-typical", "f64"), ("leuven-typical", "f64"), ("haessig1991-bristle", "f64"),
    ("dahl1968", "fixed"), ("xiong-typical", "f32"),
])
def test_simulate_is_the_cli(cli, tmp_path, name, scalar):
    """Every force equals the CLI's `f` column (printed to 13 digits)."""
    path = PARAMS / f"{name}.toml"
    t, v = signal()
    ours = friction.load(path).simulate(t, v, scalar=scalar)
    theirs = cli_simulate(cli, tmp_path, path, t, v, scalar)
    assert len(ours) == len(theirs) == len(t)
    for k, (a, b) in enumerate(zip(ours, theirs)):
        assert float(f"{a:.12e}") == float(b), f"row {k}: {a!r} vs {b}"


def test_keywords_build_the_same_model_as_the_file():
    t, v = signal()
    file = friction.load(PARAMS / "canudas1995.toml")
    kw = friction.Model("lugre", fc=1.0, fs=1.5, vs=1e-3, stribeck_exponent=2,
                        sigma0=1e5, sigma1=316.22776601683794, sigma2=0.4)
    assert kw.name == "lugre" and kw.observable
    np.testing.assert_array_equal(kw.simulate(t, v), file.simulate(t, v))
    gms = friction.Model(
        "gms", fc=1.0, fs=1.5, vs=1e-3, stribeck_exponent=2, sigma2=0.4, c=1000.0,
        elements=[
            {"k": 2.5e4, "alpha": 0.4, "sigma1": 2.5},
            {"k": 5e4, "alpha": 0.3, "sigma1": 5.0},
            {"k": 1e5, "alpha": 0.2, "sigma1": 10.0},
            {"k": 2e5, "alpha": 0.1, "sigma1": 20.0},
        ],
    )
    assert gms.name == "gms" and len(gms.simulate(t, v)) == len(t)


@pytest.mark.parametrize("kwargs,word", [
    ({"sigma0": -1.0}, "sigma0"),
    ({"sigma1": float("nan")}, "sigma1"),
    ({"fs": 0.5}, "fs"),
    ({"sigma0": 1e30}, "sigma0"),
    ({"sigma0": "stiff"}, "sigma0"),
])
def test_invalid_parameters_name_the_parameter(kwargs, word):
    params = dict(fc=1.0, fs=1.5, vs=1e-3, stribeck_exponent=2, sigma0=1e5, sigma1=316.0, sigma2=0.4)
    params.update(kwargs)
    with pytest.raises(ValueError, match=word):
        friction.Model("lugre", **params)


def test_unknown_keywords_raise_type_error():
    params = dict(fc=1.0, fs=1.5, vs=1e-3, stribeck_exponent=2, sigma0=1e5, sigma1=316.0, sigma2=0.4)
    with pytest.raises(TypeError, match="sigmaX"):
        friction.Model("lugre", sigmaX=1.0, **params)
    with pytest.raises(TypeError, match="model"):
        friction.Model("lugre", model="dahl", **params)


def test_bad_calls_raise_value_error(tmp_path):
    m = friction.load(PARAMS / "canudas1995.toml")
    t, v = signal(100)
    with pytest.raises(ValueError, match="same length"):
        m.simulate(t, v[:-1])
    with pytest.raises(ValueError, match="scalar"):
        m.simulate(t, v, scalar="f16")
    with pytest.raises(ValueError, match="empty"):
        m.simulate(t[:0], v[:0])
    with pytest.raises(ValueError, match="period|time step"):
        m.simulate(np.array([0.0, 1e-3, 3e-3]), np.zeros(3), scalar="fixed")
    with pytest.raises(ValueError, match="model"):
        friction.Model("stribek", fc=1.0)
    with pytest.raises(ValueError, match="cannot read"):
        friction.load(tmp_path / "missing.toml")
    bad = tmp_path / "bad.toml"
    bad.write_text('model = "lugre"\nfc = 1.0\nfs = \n')
    with pytest.raises(ValueError, match="line 3"):
        friction.load(bad)
    with pytest.raises(ValueError, match="no observer"):
        friction.Model("coulomb", fc=1.0).observer(100.0, 1e-3)


def test_observer_tracks_the_friction_of_its_own_model():
    """A position trajectory whose friction is the model's own: the
    observer's estimate follows the model's force once converged."""
    m = friction.load(PARAMS / "olsson1998-servo.toml")
    h = 1e-3
    t = np.arange(3000) * h
    x = 0.05 * np.sin(2 * np.pi * 0.5 * t)
    v = np.gradient(x, h)
    truth = m.simulate(t, v)
    est = m.observer(200.0, h).run(x, x)  # no error: the open-loop model
    err = np.abs(est[1000:] - truth[1000:])
    assert np.all(np.isfinite(est))
    assert err.max() < 0.1 * 0.33, err.max()


def test_compensator_tick_and_adaptation():
    m = friction.load(PARAMS / "olsson1998-servo.toml")
    w, j = 2 * np.pi * 10, 0.0023
    c = m.compensator(h=1e-3, kp=j * w * w, kd=2 * j * w, inertia=j, limit=5.0)
    u, f = c.tick(0.0, 1e-3)
    assert abs(u) <= 5.0 and np.isfinite(f)
    a = m.compensator(h=1e-3, kp=j * w * w, kd=2 * j * w, inertia=j, limit=5.0,
                      adaptive={"gamma": 50.0})
    assert a.adapted() == {"theta": 1.0}
    x = np.arange(500) * 1e-5
    u, f = a.run(x - 1e-4, x, np.full(500, 1e-2), np.zeros(500))
    assert np.all(np.abs(u) <= 5.0)
    assert a.adapted()["theta"] != 1.0
    with pytest.raises(TypeError, match="unknown key"):
        m.compensator(h=1e-3, kp=1.0, kd=0.0, inertia=0.0, adaptive={"gama": 1.0})
    with pytest.raises(ValueError, match="kd"):
        m.compensator(h=1e-3, kp=1.0, kd=-1.0, inertia=0.0)


def closed_loop(c, seconds, factor=1.0, asymmetry=0.0, counts=None):
    """Olsson's loop (J = 0.0023, kc = 1.02) on a Coulomb + viscous plant
    whose Coulomb level is `factor` times 0.28 N m, `1 + asymmetry` times
    forward and `1 - asymmetry` times backward, tracking 0.5 sin(2 pi 0.2 t)
    rad, the position read by an encoder of `counts` per turn (None:
    exact); returns the tracking errors and the modes after each second."""
    x = v = 0.0
    w = 2 * np.pi * 0.2
    count = 2 * np.pi / counts if counts else None
    errors, modes = [], []
    for k in range(int(seconds * 1000)):
        t = k * 1e-3
        r = 0.5 * np.sin(w * t)
        measured = round(x / count) * count if count else x
        u, _ = c.tick(measured, r, 0.5 * w * np.cos(w * t), -0.5 * w * w * np.sin(w * t))
        for _ in range(10):
            side = 1 + asymmetry if v >= 0 else 1 - asymmetry
            f = factor * side * 0.28 * np.tanh(v / 1e-3) + 0.0176 * v
            v += 1e-4 * (1.02 * u - f) / 0.0023
            x += 1e-4 * v
        errors.append(x - r)
        if k % 1000 == 999:
            modes.append(c.mode)
    return np.array(errors), modes


def test_a_velocity_observer_serves_a_12_bit_encoder():
    """On a 4096-count encoder (0.41 counts per period at the reference's
    peak speed) the per-parameter compensator with the velocity observer
    at 50 Hz tracks better than with the backward difference; the observer
    is refused beside a velocity filter and at half the rate."""
    m = friction.load(PARAMS / "olsson1998-servo.toml")
    loop = dict(h=1e-3, kp=60.0, ki=200.0, kd=1.2, inertia=0.0023,
                torque_constant=1.02, limit=10.0, gain=20.0, parameter_adaptive=True)
    rms = {}
    for observer in (None, 50.0):
        c = m.compensator(velocity_observer=observer, **loop)
        e, _ = closed_loop(c, 10.0, counts=4096)
        rms[observer] = np.sqrt(np.mean(e[len(e) // 2:] ** 2))
    assert rms[50.0] < rms[None], rms
    with pytest.raises(ValueError, match="velocity_observer: not with velocity_filter"):
        m.compensator(velocity_observer=50.0, velocity_filter=100.0, **loop)
    with pytest.raises(ValueError, match="velocity_observer"):
        m.compensator(velocity_observer=500.0, **loop)


def test_an_external_torque_reaches_the_load_input():
    """With a load term, an axis told an external torque commands otherwise
    than one told nothing (its load input is kc u - torque); a non-finite
    torque is refused."""
    m = friction.load(PARAMS / "olsson1998-servo.toml")
    loop = dict(h=1e-3, kp=60.0, ki=200.0, kd=1.2, inertia=0.0023,
                torque_constant=1.02, limit=10.0, gain=20.0)
    settings = {"load": 0.05, "load_max": 0.1}
    told = m.compensator(parameter_adaptive=settings, **loop)
    untold = m.compensator(parameter_adaptive=settings, **loop)
    told.set_external_torque(1.5)
    for bad in (float("nan"), float("inf")):
        with pytest.raises(ValueError, match="finite"):
            told.set_external_torque(bad)
    apart = 0
    for k in range(200):
        x, r = 1e-4 * np.sin(0.05 * k), 2e-4 * np.sin(0.05 * k)
        if told.tick(x, r) != untold.tick(x, r):
            apart += 1
    assert apart > 100, apart
    # a compensation without a load input ignores it
    plain = m.compensator(**loop)
    plain.set_external_torque(1.5)


def test_parameter_adaptive_compensator_and_its_supervisor():
    """The per-parameter law learns a plant whose Coulomb level differs by
    direction and stays applied; under a supervisor the mode is readable;
    bad settings are named."""
    m = friction.load(PARAMS / "olsson1998-servo.toml")
    loop = dict(h=1e-3, kp=60.0, ki=200.0, kd=1.2, inertia=0.0023,
                torque_constant=1.02, limit=10.0, gain=20.0)
    c = m.compensator(parameter_adaptive={"rate": 16.0, "speed": 0.63}, **loop)
    assert c.mode == "primary"
    a = c.adapted()
    assert set(a) == {"fc_pos", "fc_neg", "stribeck", "sigma2", "load", "stiffness", "mode"}
    assert a["stiffness"] == 1.0
    assert a["fc_pos"] == a["fc_neg"] == pytest.approx(0.28, rel=1e-9)
    assert a["mode"] == 0.0
    e, modes = closed_loop(c, 20, asymmetry=0.2)
    a = c.adapted()
    # forward 0.336, backward 0.224 N m: learnt apart
    assert a["fc_pos"] > a["fc_neg"] + 0.05, a
    assert modes[-1] == "primary", modes
    none = m.compensator(**loop)
    assert c.mode in ("primary", "fallback", "off")
    # better than the fixed observer on the asymmetric plant, over the last half
    e_obs, _ = closed_loop(none, 20, asymmetry=0.2)
    half = len(e) // 2
    assert np.sqrt(np.mean(e[half:] ** 2)) < np.sqrt(np.mean(e_obs[half:] ** 2))
    # without a supervisor: no mode
    bare = m.compensator(parameter_adaptive=True, supervisor=False, **loop)
    assert bare.mode is None and "mode" not in bare.adapted()
    # a supervisor dict
    s = m.compensator(parameter_adaptive=True, supervisor={"window": 0.05, "ratio": 0.5}, **loop)
    assert s.mode == "primary"
    with pytest.raises(TypeError, match="unknown key"):
        m.compensator(parameter_adaptive={"rte": 1.0}, **loop)
    with pytest.raises(TypeError, match="unknown key"):
        m.compensator(parameter_adaptive=True, supervisor={"windw": 1.0}, **loop)
    with pytest.raises(ValueError, match="box_factor"):
        m.compensator(parameter_adaptive={"box_factor": 0.5}, **loop)
    # the exact step (the command line's): a flag, and a different law
    exact = m.compensator(parameter_adaptive={"exact_step": True}, supervisor=False, **loop)
    e_exact, _ = closed_loop(exact, 2)
    e_implicit, _ = closed_loop(m.compensator(parameter_adaptive={"exact_step": False},
                                              supervisor=False, **loop), 2)
    assert np.max(np.abs(e_exact - e_implicit)) > 0.0
    with pytest.raises(ValueError, match="exact_step"):
        m.compensator(parameter_adaptive={"exact_step": 2}, **loop)
    # the stiffness law (its learning is the core's test): a setting whose
    # factor is read and stays in its box; off, it stays 1; a bad rate or
    # box is named
    k = m.compensator(parameter_adaptive={"exact_step": True, "stiffness_rate": 100.0,
                                          "stiffness_box": 4.0, "speed": 0.63}, **loop)
    closed_loop(k, 10)
    assert 0.25 <= k.adapted()["stiffness"] <= 4.0
    assert exact.adapted()["stiffness"] == 1.0
    with pytest.raises(ValueError, match="stiffness_box"):
        m.compensator(parameter_adaptive={"stiffness_box": 0.5}, **loop)
    with pytest.raises(ValueError, match="stiffness_rate"):
        m.compensator(parameter_adaptive={"stiffness_rate": -1.0}, **loop)
    with pytest.raises(ValueError, match="ratio"):
        m.compensator(parameter_adaptive=True, supervisor={"ratio": 2.0}, **loop)
    with pytest.raises(ValueError, match="two laws"):
        m.compensator(parameter_adaptive=True, adaptive={"gamma": 1.0}, **loop)
    with pytest.raises(ValueError, match="parameter_adaptive"):
        m.compensator(supervisor=True, **loop)
    with pytest.raises(ValueError, match="no observer"):
        friction.Model("coulomb", fc=1.0).compensator(parameter_adaptive=True, **loop)


def test_the_supervisor_falls_back_from_a_law_that_cannot_learn():
    """A law frozen (rate 0) at four times the plant's Coulomb level (and
    a fallback map of the same wrong level) predicts the measured friction
    worse than no compensation: the supervisor leaves it after the
    warm-up, and the mode says so."""
    m = friction.Model("lugre", fc=0.56, fs=0.66, vs=0.01, sigma0=260.0,
                       sigma1=0.6, sigma2=0.0176)
    loop = dict(h=1e-3, kp=60.0, ki=200.0, kd=1.2, inertia=0.0023,
                torque_constant=1.02, limit=10.0, gain=20.0)
    c = m.compensator(parameter_adaptive={"rate": 0.0}, supervisor={"tolerance": 0.003}, **loop)
    _, modes = closed_loop(c, 10, factor=0.5)
    assert modes[0] == "primary"  # the warm-up
    assert "primary" != modes[-1], modes


def test_servo_is_the_cli(cli, tmp_path):
    ours = friction.servo()
    out = subprocess.run([str(cli), "servo", "--output", str(tmp_path / "servo")],
                         check=True, capture_output=True, text=True).stdout
    lines = [l.split() for l in out.splitlines() if l.startswith("servo ")]
    assert lines and len(lines) == len(ours)
    for line in lines:
        name = line[1]
        assert name in ours
        if line[2] == "unstable":
            assert not ours[name]["stable"]
        else:
            assert f"{1e3 * ours[name]['rms']:.4f}" == line[2], name
            assert f"{1e3 * ours[name]['max']:.4f}" == line[3], name
    assert ours["observer"]["rms"] < ours["none"]["rms"] / 10


def test_identify_recovers_a_known_axis():
    """A driven mass (2 kg) with Coulomb 1.5 N and viscous 3 N s/m friction:
    the fit recovers them within 3 %, each with a finite standard deviation."""
    h = 1e-3
    t = np.arange(20000) * h
    x = 0.05 * np.sin(2 * np.pi * 0.5 * t) + 0.02 * np.sin(2 * np.pi * 1.3 * t)
    v = np.gradient(x, h)
    a = np.gradient(v, h)
    force = 2.0 * a + 1.5 * np.sign(v) + 3.0 * v
    fit = friction.identify(t, x, force, model="coulomb-viscous")
    assert abs(fit["fc"][0] - 1.5) < 0.03 * 1.5, fit
    assert abs(fit["sigma2"][0] - 3.0) < 0.03 * 3.0, fit
    assert abs(fit["mass"][0] - 2.0) < 0.03 * 2.0, fit
    assert all(np.isfinite(s) and s >= 0 for _, s in fit.values())
    with pytest.raises(ValueError, match="model"):
        friction.identify(t, x, force, model="dahl")
    with pytest.raises(ValueError, match="samples"):
        friction.identify(t[:10], x[:10], force[:10])


def test_retune_swaps_a_running_compensator_without_a_bump():
    """A measured model swapped into a running axis: the command at the
    swap differs from the unswapped one by at most the change of the
    friction estimate over kc, tracking goes on as well as with the
    measured model all along; a per-parameter law restarts at the measured
    levels; another kind of compensation is refused, the axis untouched."""
    lugre = dict(vs=0.01, sigma1=0.6)
    old = friction.Model("lugre", fc=0.28, fs=0.33, sigma0=260.0, sigma2=0.0176, **lugre)
    new = friction.Model("lugre", fc=0.36, fs=0.45, sigma0=650.0, sigma2=0.03, **lugre)
    loop = dict(h=1e-3, kp=60.0, ki=200.0, kd=1.2, inertia=0.0023,
                torque_constant=1.02, limit=10.0, gain=20.0)
    w = 2 * np.pi * 0.2

    def run(c, seconds, at=None, shadow=None):
        """The closed loop on a Coulomb + viscous plant with the measured
        levels; at tick `at` the compensator is re-tuned to `new`, and the
        swap tick is compared with `shadow` (the same axis, not re-tuned)."""
        x = v = 0.0
        errors, swap = [], None
        for k in range(int(seconds * 1000)):
            t = k * 1e-3
            r = (0.5 * np.sin(w * t), 0.5 * w * np.cos(w * t), -0.5 * w * w * np.sin(w * t))
            if k == at:
                c.retune(new, gain=20.0)
                u, f = c.tick(x, *r)
                u0, f0 = shadow.tick(x, *r)
                swap = (abs(u - u0), abs(f - f0) / 1.02)
            else:
                u, _ = c.tick(x, *r)
                if shadow is not None and (at is None or k < at):
                    shadow.tick(x, *r)
            for _ in range(10):
                f = 0.36 * np.tanh(v / 1e-3) + 0.03 * v
                v += 1e-4 * (1.02 * u - f) / 0.0023
                x += 1e-4 * v
            errors.append(x - r[0])
        return np.array(errors), swap

    c, shadow = old.compensator(**loop), old.compensator(**loop)
    e, (bump, bound) = run(c, 5, at=2300, shadow=shadow)
    assert bound > 0.01  # the estimate changed: the bound is not vacuous
    assert bump <= bound + 1e-12, (bump, bound)
    e_new, _ = run(new.compensator(**loop), 5)
    rms = lambda a: np.sqrt(np.mean(a[-1000:] ** 2))  # noqa: E731
    assert rms(e) <= 1.1 * rms(e_new), (rms(e), rms(e_new))

    # the per-parameter law restarts at the measured levels, its mode kept
    adaptive = {"rate": 16.0, "speed": 0.63}
    p = old.compensator(parameter_adaptive=adaptive, **loop)
    closed_loop(p, 2)
    assert p.adapted()["fc_pos"] != pytest.approx(0.28, rel=1e-6)
    mode = p.mode
    p.retune(new, gain=20.0, parameter_adaptive=adaptive)
    a = p.adapted()
    assert a["fc_pos"] == a["fc_neg"] == pytest.approx(0.36, rel=1e-12)
    assert a["stribeck"] == pytest.approx(0.09, rel=1e-12)
    assert a["sigma2"] == pytest.approx(0.03, rel=1e-12)
    assert p.mode == mode

    # refusals leave the axis as it was: it ticks on as its twin does
    c, twin = old.compensator(**loop), old.compensator(**loop)
    for k in range(100):
        assert c.tick(1e-5 * k, 1e-5 * k + 1e-4) == twin.tick(1e-5 * k, 1e-5 * k + 1e-4)
    with pytest.raises(ValueError, match="another kind"):
        c.retune(new, gain=20.0, adaptive={"gamma": 50.0})
    with pytest.raises(ValueError, match="another kind"):
        c.retune(new, gain=20.0, parameter_adaptive=True)
    with pytest.raises(ValueError, match="another kind"):
        c.retune(friction.load(PARAMS / "dahl1968.toml"), gain=20.0)
    with pytest.raises(ValueError, match="gain"):
        c.retune(new, gain=-1.0)
    with pytest.raises(ValueError, match="no observer"):
        c.retune(friction.Model("coulomb", fc=1.0))
    for k in range(100, 200):
        assert c.tick(1e-5 * k, 1e-5 * k + 1e-4) == twin.tick(1e-5 * k, 1e-5 * k + 1e-4)
