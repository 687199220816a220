"""Exceptions with the exit status the command line maps them to (SPEC section 2).

These are the only exceptions the package raises on purpose, through either door: the
command line maps them to exit statuses, and the Python API (``System`` and its calls,
the solver functions) raises only them for bad input or a failed solve: a value of the
wrong type, a NaN, an unknown effect, a model too large for the memory left or an argument
such as ``max_iter=0`` is an :class:`InputError` with the namelist's message."""
from __future__ import annotations


#: exceptions only a mistake in the package's own code raises, whatever the input: the doors
#: that report a damaged file's exceptions (of any type) as bad input let these through, so
#: a bug surfaces as an internal error (exit 1), not as a damaged file (exit 2)
PROGRAMMING_ERRORS = (NameError, ImportError, AssertionError, NotImplementedError,
                      SyntaxError)


class AncfError(Exception):
    """Base class of every error ancfdrv raises on purpose."""

    exit_code = 1


class InputError(AncfError):
    """Bad input: unknown group or key, wrong size, non-physical value, missing file.

    The message names the file, the namelist group and the key where they are known.
    """

    exit_code = 2

    def __init__(self, message: str, *, file: str | None = None, group: str | None = None,
                 key: str | None = None) -> None:
        self.file, self.group, self.key = file, group, key
        #: the message without the place (file, group, key) it is prefixed with
        self.reason = message
        where = []
        if file:
            where.append(str(file))
        if group:
            where.append(f"&{group}" + (f" {key}" if key else ""))
        prefix = ": ".join(where)
        super().__init__(f"{prefix}: {message}" if prefix else message)


class SolverError(AncfError):
    """A solver failed: Newton did not converge, a matrix was singular, a kernel refused."""

    exit_code = 3
    #: the output file's final status
    status = "failed"


class UnstableError(SolverError):
    """The energy of a run grew beyond ``solver.energy_tolerance`` with no work to explain
    it (the integrator's numerical instability), or a load-controlled static solve
    converged onto an unstable equilibrium (its stability index > 0): exit 3, status
    'unstable', the rows kept."""

    status = "unstable"


class Interrupted(AncfError):
    """The run was stopped on request (SIGINT or SIGTERM) at a step boundary; the output
    file holds every step computed until then and says status = 'interrupted'.

    The exit status is 128 + the signal number (130 for SIGINT, 143 for SIGTERM), the
    shell's convention for a process ended by a signal.
    """

    def __init__(self, message: str = "interrupted", *, signum: int | None = None) -> None:
        self.signum = signum
        super().__init__(message)

    @property
    def exit_code(self) -> int:  # type: ignore[override]
        import signal
        return 128 + (self.signum or signal.SIGINT)
