"""The torsion spring force element (issue 36 item 2's demonstration kind: one `case` in
fortran/src/elements/force_elements.f90 and its entry in system/kinds/force_element.py).
Checked against closed forms: its tangent and energy against central differences of the
kernel's force, its static twist M / k_t, the oscillation frequency sqrt(k_t / J) / (2 pi)
of a rigid body on a revolute joint (within the trapezoidal rule's period error
(omega h)^2 / 12), and its reaction -k_t theta about the axis."""
from __future__ import annotations

import numpy as np
import pytest

from ancfdrv import System
from ancfdrv.errors import InputError
from ancfdrv.system.kinds.force_element import FE_TORSION, ForceElementInfo, evaluate

KT, J = 40.0, 0.1                  # N m/rad, kg m^2 about z: omega = 20 rad/s
OMEGA = np.sqrt(KT / J)


def rotation(axis, angle: float) -> np.ndarray:
    k = np.asarray(axis, float) / np.linalg.norm(axis)
    s = np.array([[0, -k[2], k[1]], [k[2], 0, -k[0]], [-k[1], k[0], 0]])
    return np.eye(3) + np.sin(angle) * s + (1 - np.cos(angle)) * s @ s


def _info(kt: float, ct: float) -> ForceElementInfo:
    return ForceElementInfo("t", FE_TORSION, -1, np.array([kt, ct]), 0, np.zeros(0),
                            [None] * 5)


def _slots(turn1: np.ndarray, turn2: np.ndarray) -> np.ndarray:
    """p1, p2, g1, g2 (body1's e_x, e_y turned by turn1), h1 (body2's e_x turned by turn2)."""
    return np.column_stack([[0.1, 0.2, 0.3], [0.1, 0.2, 0.3], turn1[:, 0], turn1[:, 1],
                            turn2[:, 0]])


def test_tangent_energy_and_angle_against_closed_forms():
    """At a large common turn with a relative turn of 1.1 rad about body1's axis: theta
    exact (energy k theta^2 / 2, moment -(k theta + c theta') about the axis on body2),
    stiffness and damping against central differences of the force, the force against the
    energy's."""
    info = _info(KT, 3.0)
    common = rotation((0.4, -1.0, 0.7), 2.3)
    theta = 1.1
    x = _slots(common, common @ rotation((0, 0, 1), theta))
    rng = np.random.default_rng(7)
    xd = rng.normal(size=(3, 5))
    out = evaluate(info, x, xd)
    axis = common[:, 2]
    # theta' = d/dt atan2(g2.h1, g1.h1) from the slots' rates
    c, s = x[:, 2] @ x[:, 4], x[:, 3] @ x[:, 4]
    dc = xd[:, 2] @ x[:, 4] + x[:, 2] @ xd[:, 4]
    ds = xd[:, 3] @ x[:, 4] + x[:, 3] @ xd[:, 4]
    rate = (c * ds - s * dc) / (c**2 + s**2)
    assert out["energy"] == pytest.approx(0.5 * KT * theta**2, rel=1e-12)
    assert np.allclose(out["reaction"][3:6], -(KT * theta + 3.0 * rate) * axis, rtol=1e-12,
                       atol=1e-12 * KT)
    assert np.abs(out["reaction"][0:3]).max() == 0.0 and out["reaction"][6] == 0.0
    assert out["dissipation"] == pytest.approx(3.0 * rate**2, rel=1e-12)
    h = 1e-6
    fd_k, fd_c, fd_e = np.zeros((3, 5, 3, 5)), np.zeros((3, 5, 3, 5)), np.zeros((3, 5))
    for j in range(3):
        for w in range(5):
            d = np.zeros_like(x)
            d[j, w] = h
            fd_k[:, :, j, w] = (evaluate(info, x + d, xd)["force"]
                                - evaluate(info, x - d, xd)["force"]) / (2 * h)
            fd_c[:, :, j, w] = (evaluate(info, x, xd + d)["force"]
                                - evaluate(info, x, xd - d)["force"]) / (2 * h)
            fd_e[j, w] = (evaluate(info, x + d)["energy"] - evaluate(info, x - d)["energy"]) \
                / (2 * h)
    assert np.abs(out["stiffness"] - fd_k).max() <= 1e-6 * np.abs(out["stiffness"]).max()
    assert np.abs(out["damping"] - fd_c).max() <= 1e-6 * np.abs(out["damping"]).max()
    static = evaluate(info, x)["force"]
    assert np.abs(static - fd_e).max() <= 1e-6 * np.abs(static).max()
    # a common turn alone (any angle): no moment, no energy
    rest = evaluate(info, _slots(common, common))
    assert rest["energy"] <= 1e-28 and np.abs(rest["force"]).max() <= 1e-13 * KT


def hinged_disc(*, moment: float = 0.0, damping: float = 0.0, axis=(0, 0, 1),
                typed: bool = False) -> System:
    """A rigid disc on a revolute joint about z at its centre, held to the ground by a
    torsion spring about ``axis`` (a multiple of z), a dead moment about z; the spring
    through ``System.add`` or (``typed``) the typed ``System.force_element``."""
    s = System("torsion")
    s.rigid_body("disc", mass=1.0, inertia=(0.05, 0.05, J, 0, 0, 0), position=(0, 0, 0))
    s.joint("hinge", "revolute", "ground", "disc", point=(0, 0, 0), axis=(0, 0, 1))
    values = dict(point=(0, 0, 0), axis=axis, rotational_stiffness=KT,
                  rotational_damping=damping)
    if typed:
        s.force_element("spring", "torsion", "ground", "disc", **values)
    else:
        s.add("force_element", name="spring", type="torsion", body1="ground", body2="disc",
              **values)
    if moment:
        s.load("m", "moment", body="disc", point=(0, 0, 0), vector=(0, 0, moment))
    s.probe("x", "disc", (1, 0, 0))
    return s


@pytest.mark.parametrize("typed", [False, True], ids=["add", "typed"])
@pytest.mark.parametrize("moment", [0.8, 24.0])
def test_static_twist_is_the_moment_over_the_stiffness(moment, typed):
    """A moment M about the hinge: the disc turns by M / k_t (exact for any angle: the
    measure is the angle itself; 0.02 and 0.6 rad), the spring's reaction is -M; the same
    through System.add and the typed System.force_element."""
    res = hinged_disc(moment=moment, axis=(0, 0, 2.5), typed=typed).static(
        static_method="newton")
    x = np.asarray(res.probes["x"]).ravel()
    assert np.arctan2(x[1], x[0]) == pytest.approx(moment / KT, rel=1e-9)
    assert np.allclose(res.reactions["spring"]["moment"], [0, 0, -moment], rtol=1e-9,
                       atol=1e-9 * moment)


def test_oscillation_frequency_of_the_hinged_disc():
    """A moment M switched on at t = 0: theta = M / k_t (1 - cos omega t), omega =
    sqrt(k_t / J); the trapezoidal rule lengthens the period by (omega h)^2 / 12."""
    dt, moment = 2e-3, 0.4
    res = hinged_disc(moment=moment).simulate(t_end=1.0, dt=dt)
    t = np.asarray(res.time)
    x = np.asarray(res.probes["x"])
    y = np.arctan2(x[:, 1], x[:, 0]) - moment / KT
    idx = np.nonzero(np.diff(np.sign(y)) != 0)[0]
    crossings = t[idx] - y[idx] * (t[idx + 1] - t[idx]) / (y[idx + 1] - y[idx])
    period = 2 * np.mean(np.diff(crossings))
    elongation = period * np.sqrt(KT / J) / (2 * np.pi) - 1
    assert len(crossings) >= 5
    # measured 1.3329e-4 against (omega h)^2 / 12 = 1.3333e-4
    assert elongation == pytest.approx((OMEGA * dt)**2 / 12, rel=1e-2)
    assert np.abs(y + moment / KT).max() == pytest.approx(2 * moment / KT, rel=1e-3)


def test_bad_torsion_input_names_the_item():
    s = System()
    s.rigid_body("disc", mass=1.0, inertia=(0.05, 0.05, J, 0, 0, 0), position=(0, 0, 0))
    with pytest.raises(InputError, match=r"force element 'k'.*torsion.*needs.*axis"):
        s.add("force_element", name="k", type="torsion", body1="ground", body2="disc",
              point=(0, 0, 0), rotational_stiffness=KT)
    with pytest.raises(InputError, match=r"force element 'k'.*axis must be a nonzero"):
        s.add("force_element", name="k", type="torsion", body1="ground", body2="disc",
              point=(0, 0, 0), axis=(0, 0, 0), rotational_stiffness=KT)
    with pytest.raises(InputError, match=r"force element 'k'.*does not take stiffness"):
        s.add("force_element", name="k", type="torsion", body1="ground", body2="disc",
              point=(0, 0, 0), axis=(0, 0, 1), rotational_stiffness=KT, stiffness=1.0)
