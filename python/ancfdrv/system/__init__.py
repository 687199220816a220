"""Compose any system: bodies, joints, drives, loads, contacts and probes (SPEC section 8).

:class:`System` collects named items and :meth:`System.assemble` builds the
:class:`~.model.Model` the solvers run. Modules: ``sections`` (beam cross-sections),
``bodies``, ``drives``, ``joints``, ``loads``, ``contact``, ``probes``, ``system`` (the
container and its name checks), ``assembly`` (numbering, elimination of linear joints,
patterns, the kernel handle), ``model`` (the assembled model).
"""
from .bodies import Material
from .kinds import Beam, Cable, Leaf, Plate, RigidBody
from .drives import Constant, Cycle, Drive, Luffing, Ramp, Sine, SpinUp, Table
from .model import Model
from .sections import Box, Circle, General, Rectangle, Section, Standard, Tube
from .system import System

__all__ = ["System", "Model", "Material", "Beam", "Cable", "Plate", "Leaf", "RigidBody", "Section",
           "Rectangle", "Box", "Tube", "Circle", "General", "Standard", "Drive", "Constant", "Luffing", "Ramp",
           "SpinUp",
           "Cycle", "Sine", "Table"]
