"""Models of the long-run stability suite (issue 26), shared by benchmarks/stability.py and
tests/test_step_control.py.

* the flexible double pendulum: two hinged beams 1 m, 0.02 x 0.02 m, E = 2e9 Pa,
  rho = 2700 kg/m^3 ('nonlinear' ANCF beams), released horizontal under gravity;
* the flexible pendulum (Berzeri & Shabana 2000): inputs/hard/pendulum.nml.
"""
from __future__ import annotations

from ancfdrv import Rectangle, System

G = 9.81


def double_pendulum(nodes: int = 5) -> System:
    """Two flexible beams (0,0,0)-(1,0,0)-(2,0,0) hinged about z to the ground and to each
    other, gravity -y; probes 'knee' (1,0,0) and 'tip' (2,0,0)."""
    s = System("flexible double pendulum")
    mat = s.material("alu", youngs_modulus=2e9, density=2700.0)
    sec = Rectangle(0.02, 0.02)
    s.beam("upper", material=mat, start=(0, 0, 0), end=(1, 0, 0), nodes=nodes, section=sec,
           formulation="nonlinear")
    s.beam("lower", material=mat, start=(1, 0, 0), end=(2, 0, 0), nodes=nodes, section=sec,
           formulation="nonlinear")
    s.joint("shoulder", "revolute", "ground", "upper", point=(0, 0, 0), axis=(0, 0, 1))
    s.joint("elbow", "revolute", "upper", "lower", point=(1, 0, 0), axis=(0, 0, 1))
    s.load("g", "gravity", vector=(0, -G, 0))
    s.probe("knee", "upper", (1, 0, 0))
    s.probe("tip", "lower", (2, 0, 0))
    return s
