"""friction.Commissioning against a plant written here in Python: a mass on
LuGre friction (the bristle state integrated exactly over each sub-step, the
mass semi-implicitly), ticked as a notebook would tick it. The routine must
find the plant's Coulomb level and viscous coefficient within 5 %, stop a
stuck axis with a reason, and refuse bad settings by name."""

import math

import pytest

import friction

# the loop of the core's commissioning tests (1 kHz, Olsson et al. 1998's
# servo inertia and torque constant)
LOOP = dict(h=1e-3, kp=60.0, ki=200.0, kd=1.2, inertia=0.0023,
            torque_constant=1.02, limit=10.0)

# a plant whose Stribeck branch the loop can hold (the core test
# `identifies_a_stribeck_branch_the_loop_can_hold`)
PLANT = dict(fc=0.3, fs=0.42, vs=0.1, sigma0=400.0, sigma1=0.5, sigma2=0.03)


class LuGrePlant:
    """dz/dt = v - sigma0 |v| z / g(v), F = sigma0 z + sigma1 dz/dt + sigma2 v,
    J dv/dt = kc u - F, with `steps` sub-steps a tick."""

    def __init__(self, p, inertia, kc, h, steps=20):
        self.p, self.inertia, self.kc = p, inertia, kc
        self.hp = h / steps
        self.steps = steps
        self.x = self.v = self.z = 0.0

    def g(self, v):
        p = self.p
        return p["fc"] + (p["fs"] - p["fc"]) * math.exp(-((v / p["vs"]) ** 2))

    def step(self, command):
        p, hp = self.p, self.hp
        for _ in range(self.steps):
            v = self.v
            rate = p["sigma0"] * abs(v) / self.g(v)
            # z relaxes towards v / rate exactly while v is held (stable at
            # any stiffness)
            if rate > 0.0:
                target = v / rate
                z = target + (self.z - target) * math.exp(-rate * hp)
            else:
                z = self.z + v * hp
            dz = (z - self.z) / hp
            self.z = z
            f = p["sigma0"] * z + p["sigma1"] * dz + p["sigma2"] * v
            self.v += hp * (self.kc * command - f) / self.inertia
            self.x += hp * self.v


def commission(routine, plant, ticks=40_000):
    for _ in range(ticks):
        u = routine.tick(plant.x)
        assert math.isfinite(u) and abs(u) <= LOOP["limit"]
        if routine.phase in ("done", "aborted"):
            assert u == 0.0
            return
        plant.step(u)
    raise AssertionError("the routine outlived its duration")


@pytest.mark.parametrize("scalar", ["f64", "f32"])
def test_commissions_a_python_plant_within_5_percent(scalar):
    routine = friction.Commissioning(travel=1.0, max_speed=2.0, scalar=scalar, **LOOP)
    assert routine.phase == "breakaway" and routine.abort is None
    plant = LuGrePlant(PLANT, LOOP["inertia"], LOOP["torque_constant"], LOOP["h"])
    commission(routine, plant)
    assert routine.phase == "done", routine.abort
    assert routine.ticks * LOOP["h"] <= 30.0
    r = routine.result()
    for name in ("fc", "sigma2"):
        error = (r[name] - PLANT[name]) / PLANT[name]
        print(f"{scalar} {name}: {r[name]:.5f} (plant {PLANT[name]}, {error:+.2%})")
        assert abs(error) <= 0.05, (name, r[name], error)
    for direction in ("pos", "neg"):
        assert abs(r[f"fc_{direction}"] - PLANT["fc"]) <= 0.05 * PLANT["fc"]
    assert r["identified"]["coulomb"] and r["identified"]["viscous"]
    assert set(r["identified"]) == {"coulomb", "stribeck", "viscous", "stiffness", "damping", "load"}
    # no load along the window: no load coefficient
    assert not r["identified"]["load"] and r["load"] == 0.0 and r["load_torque"] > 0.0
    assert 0.0 <= r["residual"] <= 0.1
    lo, hi = r["speed_range"]
    assert 0.0 < lo < hi <= 2.0 * 1.05
    assert r["plateaus"] >= 6
    points = routine.plateau_points()
    assert len(points) >= r["plateaus"]
    # the model goes to a compensator and re-tunes a running one
    model = r["model"]
    assert model.name == "lugre"
    axis = model.compensator(**{k: LOOP[k] for k in ("h", "kp", "kd", "inertia")})
    axis.tick(0.0, 1e-3)
    axis.retune(model)
    u, _ = axis.tick(0.0, 1e-3)
    assert math.isfinite(u)


def test_a_stuck_axis_aborts_and_the_result_says_why():
    routine = friction.Commissioning(travel=1.0, max_speed=2.0, **LOOP)
    with pytest.raises(RuntimeError, match="not finished"):
        routine.result()
    for _ in range(20_000):
        u = routine.tick(0.0)
        assert abs(u) <= LOOP["limit"]
        if routine.phase != "breakaway":
            break
    assert (routine.phase, routine.abort) == ("aborted", "no_breakaway")
    assert routine.tick(0.0) == 0.0
    with pytest.raises(RuntimeError, match="aborted: no_breakaway"):
        routine.result()


def test_a_nan_position_aborts():
    routine = friction.Commissioning(travel=1.0, max_speed=2.0, **LOOP)
    routine.tick(0.0)
    assert routine.tick(float("nan")) == 0.0
    assert (routine.phase, routine.abort) == ("aborted", "non_finite")


def test_bad_settings_are_named():
    with pytest.raises(ValueError, match="speeds"):
        friction.Commissioning(travel=1.0, max_speed=2.0, speeds=17, **LOOP)
    with pytest.raises(ValueError, match="travel"):
        friction.Commissioning(travel=-1.0, max_speed=2.0, **LOOP)
    with pytest.raises(ValueError, match="plateau"):
        friction.Commissioning(travel=1.0, max_speed=2.0, plateau=5.0, **LOOP)
    with pytest.raises(ValueError, match="scalar"):
        friction.Commissioning(travel=1.0, max_speed=2.0, scalar="fixed", **LOOP)
    with pytest.raises(TypeError, match="platau"):
        friction.Commissioning(travel=1.0, max_speed=2.0, platau=0.5, **LOOP)
