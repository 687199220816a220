"""Integer codes and array layouts shared with the Fortran kernel, in one place.

Each value here mirrors an ``integer, parameter`` of a kernel module (named in the comment);
``tests/test_codes.py`` reads the Fortran sources and checks that every value agrees.
"""
from __future__ import annotations

# fortran/src/system/constraints.f90
CONSTRAINT_COORDINATE, CONSTRAINT_DISTANCE, CONSTRAINT_CROSS, CONSTRAINT_DOT = 1, 2, 3, 4

# fortran/src/system/drives.f90
DRIVE_CONSTANT, DRIVE_LUFFING, DRIVE_SPINUP, DRIVE_CYCLE, DRIVE_SINE, DRIVE_TABLE = 0, 1, 2, 3, 4, 5
#: the smooth drives of issue 22 (fortran/src/system/drives.f90 kinds 10 and 11)
DRIVE_RAMP, DRIVE_HERMITE = 10, 11

# fortran/src/elements/beam_section.f90
SECTION_RECTANGLE, SECTION_BOX, SECTION_TUBE, SECTION_CIRCLE = 1, 2, 3, 4
MAX_SECTION_POINTS = 18

# fortran/src/system/mechanical_system.f90: the iteration matrix's policy
POLICY_CONSTANT, POLICY_REFACTOR = 0, 1
#: energy(:) of an output row (mechanical_system energy_* / work_* indices, 1-based there)
ENERGY_NAMES = ("kinetic", "strain", "gravity", "moment", "total", "drive_work", "frame_work",
                "contact", "damping_work", "friction_work", "material_damping_work")
#: work(:) accumulated by the stepper (mechanical_system power_* indices)
POWER_NAMES = ("drive", "frame", "contact_damping", "friction", "material_damping")

# fortran/src/solvers/time_integrator.f90: when the iteration matrix is refreshed
JACOBIAN_STEP, JACOBIAN_ITERATION, JACOBIAN_REUSE = 1, 2, 3
#: per-step statistics (time_integrator stat_* indices)
STAT_NAMES = ("corrections", "factorizations", "jacobians")

# fortran/src/system/leaf_contact.f90
CONTACT_RECORD = ("penetration", "normal_force", "friction_force", "slip_speed", "xi", "eta")
CONTACT_COUNTERS = ("contact_points", "contact_active", "friction_evaluations",
                    "contact_projection_iterations", "contact_projection_fallbacks",
                    "contact_jacobian_dropped")
#: contact_params layout (leaf_contact cp_*)
CONTACT_PARAMS = ("stiffness", "damping", "friction", "slip_velocity", "upper_thickness",
                  "lower_thickness", "friction_on")

#: failure codes of time_integrator.integrator_chunk (status(2) of system_advance)
STEP_FAILURES = {
    1: "Newton did not converge within {max_newton} iterations",
    2: "the state became non-finite (NaN or overflow)",
    3: "the linear solve failed (solver code {detail}: -10 = singular matrix)",
    4: "the multipliers' Schur complement is singular (dgesv info {detail}): the "
       "constraints are redundant or lost rank",
    5: "a constraint or drive could not be evaluated",
    6: "a bending moment's section director became parallel to its axis",
    7: "a plate element's mid-surface normal vanished (r_x parallel to r_y: the element "
       "folded onto a line)",
    8: "the contact search found no closest point on the upper surface (the projection "
       "diverged even from the sampled restart)",
    9: "the kernel refused the call (a stale handle or inconsistent sizes: a bug)",
    10: "a force element's two points coincide (its line of action is undefined) or its "
        "force table could not be evaluated",
}
