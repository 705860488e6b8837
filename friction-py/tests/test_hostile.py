"""One table of hostile inputs sent through every front end that has the
entry point: the `friction` command line, the Python package and (where
the C ABI has the same call) the C ABI through ctypes. Each must refuse,
naming the same parameter in its own spelling: the CLI with exit code 2
and the flag, file key or CSV column; Python with ValueError (TypeError
for an unknown keyword) naming the keyword argument or the array and its
index, never a command-line flag; C with a failed status and the
parameter's name in `friction_error`."""

import ctypes
import math
import os
import pathlib
import re
import subprocess

import numpy as np
import pytest

import friction

ROOT = pathlib.Path(__file__).resolve().parents[2]
PARAMS = ROOT / "params"
SERVO = PARAMS / "olsson1998-servo.toml"
LUGRE = dict(fc=0.28, fs=0.33, vs=0.01, stribeck_exponent=2, sigma0=260.0,
             sigma1=0.6, sigma2=0.0176)
LOOP = dict(h=1e-3, kp=60.0, kd=1.2, inertia=0.0023, ki=200.0,
            torque_constant=1.02, limit=10.0)


def lugre_toml(**changes):
    p = dict(LUGRE, **changes)
    return 'model = "lugre"\n' + "".join(f"{k} = {v!r}\n" for k, v in p.items())


def nan_inf(x):
    x = float(x)
    return repr(x) if math.isfinite(x) else ("nan" if math.isnan(x) else "inf")


# --- the command line's side: a function of the temporary folder giving
# the arguments (files written there)

def cli_simulate(t, v, toml=None, scalar="f64"):
    def run(tmp):
        params = tmp / "p.toml"
        params.write_text(toml or lugre_toml())
        inp = tmp / "in.csv"
        inp.write_text("t,v\n" + "".join(f"{nan_inf(a)},{nan_inf(b)}\n" for a, b in zip(t, v)))
        return ["simulate", "--params", str(params), "--input", str(inp),
                "--output", str(tmp / "out.csv"), "--scalar", scalar]
    return run


def cli_servo(servo, toml=None):
    def run(tmp):
        params = tmp / "p.toml"
        params.write_text((toml or SERVO.read_text()) + "\n[servo]\n" + servo + "\n")
        return ["servo", "--params", str(params), "--output", str(tmp / "servo")]
    return run


def trajectory(n=600, h=1e-3):
    t = np.arange(n) * h
    x = 0.01 * np.sin(2 * np.pi * 2 * t)
    f = 0.3 * np.tanh(np.gradient(x, h) / 1e-3) + 0.002 * np.gradient(x, h)
    return t, x, f


def cli_identify(*flags):
    def run(tmp):
        t, x, f = trajectory()
        inp = tmp / "in.csv"
        inp.write_text("t,x,f\n" + "".join(f"{float(a)!r},{float(b)!r},{float(c)!r}\n"
                                            for a, b, c in zip(t, x, f)))
        return ["identify", "--input", str(inp), "--model", "coulomb-viscous",
                "--output", str(tmp / "id"), "--quiet", *flags]
    return run


def py_identify(**kw):
    return lambda: friction.identify(*trajectory(), model="coulomb-viscous", **kw)


def py_model(**changes):
    return lambda: friction.Model("lugre", **dict(LUGRE, **changes))


def py_compensator(**changes):
    def run():
        kw = dict(LOOP, **changes)
        return friction.load(SERVO).compensator(**kw)
    return run


T = np.arange(5) * 1e-3
V = np.full(5, 1e-3)


def with_sample(a, k, x):
    a = a.copy()
    a[k] = x
    return a


# --- the C ABI's side (ctypes over the cdylib)

class Stribeck(ctypes.Structure):
    _fields_ = [(n, ctypes.c_double) for n in ("fc", "fs", "vs", "exponent")]


class LuGreParams(ctypes.Structure):
    _fields_ = [("curve", Stribeck)] + [
        (n, ctypes.c_double) for n in ("sigma0", "sigma1", "sigma2", "vd")]


class ServoParams(ctypes.Structure):
    _fields_ = [(n, ctypes.c_double) for n in
                ("h", "kp", "ki", "kd", "inertia", "torque_constant", "limit")]


class AdaptiveParams(ctypes.Structure):
    _fields_ = [(n, ctypes.c_double) for n in
                ("gamma", "gamma_derivative", "leakage", "theta0", "theta_min", "theta_max")]


class Error(ctypes.Structure):
    _fields_ = [("status", ctypes.c_int32), ("parameter", ctypes.c_uint8 * 32)]


# caller-allocated objects: generous buffers, whatever the sizes in the header
OBJECT_BYTES = 1 << 14


@pytest.fixture(scope="session")
def ffi():
    """The C ABI's shared library: $FRICTION_FFI_LIB, else the debug build
    (built here when missing)."""
    path = os.environ.get("FRICTION_FFI_LIB")
    if not path:
        path = ROOT / "target" / "debug" / "libfriction_ffi.so"
        if not path.exists():
            subprocess.run(["cargo", "build", "--quiet", "-p", "friction-ffi"], cwd=ROOT, check=True)
    return ctypes.CDLL(str(path))


def lugre_params(**changes):
    p = dict(LUGRE, **changes)
    return LuGreParams(Stribeck(p["fc"], p["fs"], p["vs"], p["stribeck_exponent"]),
                       p["sigma0"], p["sigma1"], p["sigma2"], 0.0)


def c_model(**changes):
    def run(lib):
        model, err = ctypes.create_string_buffer(OBJECT_BYTES), Error()
        status = lib.friction_lugre_init_f64(model, ctypes.byref(lugre_params(**changes)),
                                             ctypes.c_double(0.0), ctypes.byref(err))
        return status, err
    return run


def c_servo(adaptive=None, velocity_observer=None, **changes):
    def run(lib):
        model, servo, err = (ctypes.create_string_buffer(OBJECT_BYTES),
                             ctypes.create_string_buffer(OBJECT_BYTES), Error())
        p = dict(LOOP, **changes)
        assert lib.friction_lugre_init_f64(model, ctypes.byref(lugre_params()),
                                           ctypes.c_double(0.0), ctypes.byref(err)) == 0
        loop = ServoParams(p["h"], p["kp"], p["ki"], p["kd"], p["inertia"],
                           p["torque_constant"], p["limit"])
        a = None
        if adaptive is not None:
            d = dict(dict(gamma=0.0, gamma_derivative=0.0, leakage=0.0, theta0=1.0,
                          theta_min=0.2, theta_max=5.0), **adaptive)
            a = ctypes.byref(AdaptiveParams(**d))
        status = lib.friction_servo_init_f64(servo, ctypes.byref(loop), model,
                                             ctypes.c_double(200.0), a, ctypes.byref(err))
        if status == 0 and velocity_observer is not None:
            status = lib.friction_servo_velocity_observer_f64(
                servo, ctypes.c_double(velocity_observer), ctypes.byref(err))
        return status, err
    return run


# (case, parameter named by the CLI, by Python, by C; CLI arguments, Python
# call and its exception, C call)
CASES = [
    ("nan velocity", "(`v`)", "`v`[2]", None,
     cli_simulate(T, with_sample(V, 2, math.nan)),
     lambda: friction.load(SERVO).simulate(T, with_sample(V, 2, math.nan)), ValueError, None),
    ("infinite velocity", "(`v`)", "`v`[3]", None,
     cli_simulate(T, with_sample(V, 3, math.inf)),
     lambda: friction.load(SERVO).simulate(T, with_sample(V, 3, math.inf)), ValueError, None),
    ("reversed time", "(`t`)", "`t`[1]", None,
     cli_simulate(T[::-1], V), lambda: friction.load(SERVO).simulate(T[::-1].copy(), V),
     ValueError, None),
    ("constant time", "(`t`)", "`t`[1]", None,
     cli_simulate(np.zeros(5), V), lambda: friction.load(SERVO).simulate(np.zeros(5), V),
     ValueError, None),
    ("fixed-point step of 1e308 s", "in.csv:3", "`t`[1]", None,
     cli_simulate([0.0, 1e308], [0.0, 0.0], scalar="fixed"),
     lambda: friction.load(SERVO).simulate(np.array([0.0, 1e308]), np.zeros(2), scalar="fixed"),
     ValueError, None),
    ("filter order 17", "--filter-order 17", "order=17", None,
     cli_identify("--filter-order", "17"), py_identify(order=17), ValueError, None),
    ("filter order 0", "--filter-order 0", "order=0", None,
     cli_identify("--filter-order", "0"), py_identify(order=0), ValueError, None),
    ("decimate 0", "--decimate 0", "decimate=0", None,
     cli_identify("--decimate", "0"), py_identify(decimate=0), ValueError, None),
    ("Stribeck exponent 1e9", "--stribeck-exponent", "stribeck_exponent=", None,
     cli_identify("--stribeck-exponent", "1e9"), py_identify(stribeck_exponent=1e9),
     ValueError, None),
    ("cut-off above Nyquist", "--cutoff 600", "cutoff=600", None,
     cli_identify("--cutoff", "600"), py_identify(cutoff=600.0), ValueError, None),
    ("velocity filter 1e9 at 1 kHz", "`velocity_filter`", "velocity_filter=", None,
     cli_servo("velocity_filter = 1e9"), py_compensator(velocity_filter=1e9), ValueError, None),
    ("velocity observer at half the rate", "`velocity_observer`", "velocity_observer",
     "velocity_observer", cli_servo("velocity_observer = 500"),
     py_compensator(velocity_observer=500.0), ValueError, c_servo(velocity_observer=500.0)),
    ("theta_max 1e-300", "`theta_max`", '"theta_max"', None,
     cli_servo("theta_max = 1e-300"),
     lambda: py_compensator(adaptive={"theta_max": 1e-300})(), ValueError, None),
    ("theta_min above 1", "`theta_min`", '"theta_min"', None,
     cli_servo("theta_min = 2"),
     lambda: py_compensator(adaptive={"theta_min": 2.0})(), ValueError, None),
    ("theta0 outside its bounds", None, '"theta0"', "theta0",
     None, lambda: py_compensator(adaptive={"theta0": 100.0})(), ValueError,
     c_servo(adaptive={"theta0": 100.0})),
    ("negative stiffness", "`sigma0`", "`sigma0`", "sigma0",
     cli_simulate(T, V, toml=lugre_toml(sigma0=-1.0)), py_model(sigma0=-1.0), ValueError,
     c_model(sigma0=-1.0)),
    ("static below Coulomb", "`fs`", "`fs`", "fs",
     cli_simulate(T, V, toml=lugre_toml(fs=0.1)), py_model(fs=0.1), ValueError,
     c_model(fs=0.1)),
    ("NaN damping", "`sigma1`", "`sigma1`", "sigma1",
     cli_simulate(T, V, toml=lugre_toml(sigma1=math.nan)),
     py_model(sigma1=math.nan), ValueError, c_model(sigma1=math.nan)),
    ("negative gain kp", "`kp`", "`kp`", "kp",
     cli_servo("kp = -60"), py_compensator(kp=-60.0), ValueError, c_servo(kp=-60.0)),
    ("zero command limit", "`limit`", "`limit`", "limit",
     cli_servo("limit = 0"), py_compensator(limit=0.0), ValueError, c_servo(limit=0.0)),
    ("unknown key", "sigmaX", "sigmaX", None,
     cli_simulate(T, V, toml=lugre_toml() + "sigmaX = 1\n"), py_model(sigmaX=1.0), TypeError,
     None),
    ("the model named twice", "model", "`model`", None,
     cli_simulate(T, V, toml=lugre_toml() + 'model = "dahl"\n'),
     lambda: friction.Model("lugre", model="dahl", **LUGRE), TypeError, None),
]


@pytest.mark.parametrize("case", CASES, ids=[c[0] for c in CASES])
def test_every_front_end_refuses_naming_the_same_parameter(case, cli, ffi, tmp_path):
    name, cli_name, py_name, c_name, cli_args, py_call, py_error, c_call = case
    if cli_args is not None:
        out = subprocess.run([str(cli), *cli_args(tmp_path)], capture_output=True, text=True)
        assert out.returncode == 2, f"{name}: exit {out.returncode}: {out.stderr}"
        assert cli_name in out.stderr, f"{name}: {out.stderr}"
        assert "panicked" not in out.stderr
    with pytest.raises(py_error) as e:
        py_call()
    message = str(e.value)
    assert py_name in message, f"{name}: {message}"
    # no command-line spelling in Python's messages
    assert not re.search(r"--[a-z]", message), f"{name}: {message}"
    if c_call is not None:
        status, err = c_call(ffi)
        assert status != 0 and err.status == status, name
        assert bytes(err.parameter).split(b"\0")[0].decode() == c_name, name


def test_a_garbled_adaptive_dict_gets_a_clear_sentence():
    with pytest.raises(ValueError) as e:
        py_compensator(adaptive={"theta0": 100})()
    assert str(e.value) == (
        'adaptive["theta0"] = 100: must be within [`theta_min`, `theta_max`] '
        "(0.2 and 5 unless given)"
    )
    with pytest.raises(TypeError, match="unknown key"):
        py_compensator(adaptive={"theta": 1.0})()
    with pytest.raises(ValueError, match="velocity_filter=0: "):
        py_compensator(velocity_filter=0.0)()
