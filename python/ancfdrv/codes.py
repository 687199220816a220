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

# fortran/src/system/system_iteration.f90: the iteration matrix's policy
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


# fortran/src/api/api_support.f90: the small arrays that group a kernel routine's related
# scalars, by the prefix of their index names (<prefix>_<name> = 1-based position there,
# <prefix>_count = the length); the f2py routines document which array has which layout
KERNEL_LAYOUTS: dict[str, tuple[str, ...]] = {
    "cs": ("area", "inertia_y", "inertia_z", "torsion", "shear_y", "shear_z", "youngs",
           "poisson"),                                   # beam_cubic_setup's section
    "bs": ("axial", "torsion", "shear_y", "shear_z", "moment_height", "moment_width", "youngs",
           "inertia_y", "inertia_z", "polar"),           # a beam set's section forces data
    "bm": ("youngs", "poisson"),                         # a continuum beam set's material
    "pm": ("youngs", "poisson", "thickness"),            # a plate's material
    "cb": ("axial_stiffness", "bending_stiffness", "damping_time", "rate_factor"),  # cable
    "fk": ("element", "table"),                          # a force element's kinds
    "fg": ("length", "length_rate"),                     # a force element's length
    "fe": ("energy", "dissipation", "drive_power"),      # a force element's energies
    "fl": ("kind", "drive", "table_kind", "slot_first"),  # system force elements (rows)
    "fp": ("param", "table", "position"),                # their pointers (columns)
    "cl": ("ncon", "nterm", "ndrive"),                   # a packed constraint layout's header
    "fm": ("rate", "sin_psi", "one_minus_cos", "accel"),  # a frame's motion (columns)
    "rs": ("dt", "beta", "gamma", "tol"),                # the reduced FFR stepper's settings
    "rc": ("pdelta", "max_newton"),                      # and controls
    "rn": ("corrections", "factorized"),                 # its per-step counts (columns)
    "rt": ("info", "failed_step"),                       # its status
    "re": ("kinetic", "strain", "power", "load"),        # reduced energy rows (columns)
    "sv": ("coordinates", "rates"),                      # a state (columns)
    "ff": ("internal", "external"),                      # system_evaluate's forces (columns)
    "ef": ("time", "load_factor", "velocity_factor"),    # system_evaluate's factors
    "ee": ("strain", "contact_potential"),               # system_evaluate's energies
    "ss": ("time", "load_factor", "tol", "length_scale", "arc", "direction"),  # a static
    # load step's or arc-length step's settings, its controls (mode: 0 Newton at the load
    # factor, 1 an arc-length step, 2 the tangent along the loads), its residual scales and
    # the path's figures, its reference configuration and previous increment (columns)
    "sc": ("check_start", "load_step", "load_steps", "mode"),
    "sr": ("force_scale", "force_res", "con_res", "load_factor", "load_norm", "tangent_norm",
           "flexibility"),
    "sx": ("reference", "previous"),
    "so": ("info", "iterations", "converged_by", "factorizations"),  # its outcome
    "sk": ("dt", "dt_min", "adaptive", "tolerance"),     # the stepper's step-size control
    "at": ("corrections", "factorizations", "jacobians", "substeps", "cuts"),  # rows' stats
    "as": ("rows", "info", "detail", "floor_accepts", "tries", "failure_cuts",
           "failure_tries", "failed_corrections", "failed_factorizations",
           "failed_jacobians", "cuts", "rejected", "restarts", "taken"),  # an advance's status
    "af": ("last_correction", "failure_t", "failure_h", "smallest"),  # and its figures
    "tp": ("rows", "cols"),                              # a pattern's coordinates (columns)
    "sl": ("handle", "policy"),                          # a solver
    "cg": ("a", "b", "xi", "eta"),                       # a contact pair's side
    "ce": ("potential", "damping", "friction"),          # contact energies
}


def mesh_parts(bodies: str) -> dict[str, tuple[str, range]]:
    """The items of a result file's mesh from /model/mesh's ``bodies`` attribute (written
    by results/xdmf.py, one 'name: kind, points a..b' line per item): {name: (kind, the
    rows of /model/mesh/points)}. Read by the writer's own node fields and by the plots,
    which read result files without the package's system."""
    parts = {}
    for line in bodies.splitlines():
        name, _, rest = line.rpartition(": ")
        kind, _, points = rest.partition(", points ")
        if ".." in points:
            first, last = (int(v) for v in points.split(".."))
            parts[name] = (kind, range(first, last + 1))
    return parts
