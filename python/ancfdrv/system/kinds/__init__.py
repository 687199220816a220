"""The kinds of items a system is made of, one module each (SPEC section 9): ``beam``
(the 'ffr', 'continuum' and 'cubic' beams), ``cable`` (cable and rope), ``plate`` (plate and
leaf), ``rigid_body``, ``force_element``. Each declares its :class:`~..registry.Kind`
(namelist group and keys, body class, API entry, element set and kernel adder, ...) when
imported; no kind module imports another."""
from . import beam, cable, force_element, plate, rigid_body  # noqa: F401  (registers each)
from .beam import Beam
from .cable import Cable
from .force_element import ForceElement
from .plate import Leaf, Plate
from .rigid_body import RigidBody

__all__ = ["Beam", "Cable", "ForceElement", "Leaf", "Plate", "RigidBody"]
