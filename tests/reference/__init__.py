"""Independent reference computations used by the tests only (never by a run).

Written without looking at ancfdrv's implementation (except the two solver references at
the end, which say so); pure numpy/scipy, SI units, every parameter passed explicitly. Their own correctness is checked against textbook closed
forms in ``tests/test_leaf_reference.py`` and ``tests/test_references.py``.

Modules
-------
``leaf_reference``
    The two-leaf spring of SPEC section 7: curved-beam Castigliano / unit-load
    integrals and the contact compatibility (see its own docstring).

``beam_formulas``
    Closed forms of linear beam theory: cantilever under tip load, uniform load, end
    moment (Euler-Bernoulli, optional Timoshenko shear term); simply supported uniform
    load; clamped-free and pinned-pinned eigenvalues beta_n L; the clamped-free beam
    with a rigid tip body (mass, rotary inertia, axial offset: transcendental frequency
    equation solved by brentq); simply supported Timoshenko frequencies (shear + rotary
    inertia); L-frame and L-grillage tip displacements by the unit-load method.

``frames``
    A linear 3D frame finite-element code (``Frame``; planar use in the x-y plane):
    Euler-Bernoulli or Timoshenko beam elements (shear coefficient per element, default 1;
    axial, torsion with J = Iy + Iz, bending in two planes; consistent mass, optional
    rotary inertia), axial bars, rigid bodies with an offset centre of mass (exact 6x6
    mass about the node), point masses, supports, hinges (revolute about any axis or
    spherical), rigid links, general linear ties, nodal loads, uniform distributed loads
    and self weight. Outputs: static displacements and reactions, lowest natural
    frequencies and mass-normalized modes. Section helpers ``rectangle``, ``box``,
    ``tube``, ``circle`` (A, Iy, Iz, J = Iy + Iz; shear area = A).

``mechanisms``
    Rigid-limit planar mechanisms: physical pendulum (rod + point mass) and double
    pendulum of two rods (Lagrange equations, solve_ivp DOP853, rtol 1e-10), their
    small-amplitude periods / frequencies; the slider-crank driven at constant crank speed
    (closed-form kinematics, driving torque by virtual work, energies); the knuckle boom
    (boom held at a given angle, jib positioned by a distance actuator of prescribed
    length, optional lift cylinder): jib angle, actuator force, hinge reactions, holding
    moment; and the small-deflection sag of the same boom made of flexible beams
    (superposition of cantilever and overhanging simply supported beam formulas).

``static_newton``
    The static Newton assembled in Python (``solve_newton_python``): the package's former
    Newton, from separate kernel force evaluations and Python's constraint Jacobians and
    Hessians; the reference of the kernel's static Newton (tests/test_static_kernel.py,
    tests/test_static_small_loads.py, benchmarks/static_kernel_gate.py).

``reduced_ffr_newmark``
    The reduced FFR model's Newmark steps in numpy with full Newton (``newmark_python``):
    the reference of the kernel's reduced stepper (tests/test_ffr_reduced.py).
"""
