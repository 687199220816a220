"""The ``ancf`` command (SPEC section 2).

    ancf [--debug] [--version] COMMAND ...
    ancf run SCENE.nml [-o OUT.h5] [--set GROUP.KEY=VALUE ...] [--plot]
    ancf sweep SCENE.nml --vary GROUP.KEY=V1,V2,... [--vary ...] [-o DIR] [--workers N | --scheduler ADDR]
    ancf info OUT.h5 [--json]
    ancf plot OUT.h5 [OUT2.h5 ...] [-o PNG]   (several files: leaf spring runs overlaid)
    ancf show SCENE.nml [-o PNG] [--set GROUP.KEY=VALUE ...]   (the model before any solve)
    ancf animate OUT.h5 [-o MP4|GIF] [--mode N] [--view xy|yz|zx]

Exit status:
    0    success
    1    internal error (a bug): one line on stderr, the full trace in a file it names;
         ``--debug`` prints the trace instead
    2    bad input: scene, override, output path refused or in use by another run, not a
         result file (the message names file, group and key)
    3    solver failure (the output file already holds what was computed, with the
         failure message in its ``message`` attribute)
    130  interrupted by SIGINT (Ctrl-C), 143 by SIGTERM: the run stopped at a step
         boundary, the output file holds every step computed and says 'interrupted'
    141  the pipe the output went to was closed (``ancf info OUT.h5 | head -1``)
"""
from __future__ import annotations

import argparse
import contextlib
import datetime as _dt
import gc
import os
import signal
import sys
import threading
import traceback
from pathlib import Path
from typing import Iterator

from ._version import __version__
from .errors import PROGRAMMING_ERRORS, AncfError, InputError, Interrupted

EXIT_CODES = """exit status:
  0    success
  1    internal error (a bug): one line, the full trace in a file it names (--debug prints it)
  2    bad input (scene, override, output path refused or in use, not a result file)
  3    solver failure (the output file holds what was computed, status 'failed'; 'unstable'
       when the energy grew beyond solver.energy_tolerance or a load-controlled static
       state is an unstable equilibrium)
  130  interrupted by SIGINT (Ctrl-C), 143 by SIGTERM (the output file holds every step
       computed, status 'interrupted')
  141  the pipe our output went to was closed (e.g. ancf info F | head -1)"""


@contextlib.contextmanager
def _imports() -> Iterator[None]:
    """Import a command's modules without the cyclic garbage collector, then keep what
    they made out of its later passes (``gc.freeze``): the modules, classes and functions
    live as long as the process, and the collector scanned them ~80 times during the
    imports of ``ancf run`` (~10 ms of its start)."""
    gc.disable()
    try:
        yield
    finally:
        gc.freeze()
        gc.enable()


def _cmd_run(args: argparse.Namespace) -> int:
    """Run a scene, print what it did and end with the headline of its answers
    (:mod:`ancfdrv.results.headline`); the plot only with --plot or output.plot."""
    with _imports():
        from .results.hdf5 import open_result, run_figures
        from .results.headline import answer_lines, answers_of
        from .runner import run_scene
    if args.force:
        args.set = [*args.set, "scene.bounds=off"]

    def plot_if_asked(done) -> list[Path]:
        # written while the output is still locked (a second run is refused meanwhile)
        wanted = args.plot or bool(done.scene["output"].get("plot", False))
        return optional_outputs(done.output) if wanted else []
    outcome = run_scene(args.scene, args.set, args.output, after=plot_if_asked)
    for warning in outcome.warnings:
        print(f"warning: {warning}", file=sys.stderr)
    with open_result(outcome.output) as h5:   # what is printed, read in one opening
        summary, answers = run_figures(h5), answers_of(h5)
    print(f"{outcome.scene['scene']['title']}")
    print(f"  model        {summary['model.nnodes']} nodes, {summary['model.ndof']} coordinates, "
          f"{summary['model.nconstraints']} constraints")
    s = outcome.static
    if s is not None:
        print(f"  static       {s.method}: {s.iterations} iterations, relative residual "
              f"{s.residual_norm:.2e}, {1e3 * s.wall_time_s:.2f} ms")
        if "static.deflection.tip" in summary:
            tip = summary["static.deflection.tip"]
            print(f"  tip          axial {1e3 * tip[0]:+.4f} mm, transverse {1e3 * tip[1]:+.4f} "
                  f"mm, lateral {1e3 * tip[2]:+.4f} mm (rigid frame)")
        for key, value in summary.items():
            if key.startswith("static.deflection.") and key != "static.deflection.tip":
                name = key.rsplit(".", 1)[1]
                print(f"  {name:12s} displacement ({1e3 * value[0]:+.4f}, {1e3 * value[1]:+.4f}, "
                      f"{1e3 * value[2]:+.4f}) mm")
        for key, value in summary.items():  # general scenes: relative to the supports
            if key.startswith("static.deflection_support."):
                name = key.rsplit(".", 1)[1]
                print(f"  {name:12s} deflection   ({1e3 * value[0]:+.4f}, {1e3 * value[1]:+.4f}, "
                      f"{1e3 * value[2]:+.4f}) mm relative to its beam's supports")
    d = outcome.dynamic
    if d is not None:
        print(f"  dynamic      {d.steps} steps of {summary['dynamic.dt']:g} s, "
              f"{d.newton_iterations / max(d.steps, 1):.2f} Newton corrections per step, "
              f"{d.factorizations} factorization{'s' if d.factorizations != 1 else ''}, "
              f"{d.wall_time_s:.2f} s")
        if outcome.stages:
            print(stage_table(outcome.stages))
    written = [str(outcome.output)] + [str(path) for path in (outcome.after or [])]
    print(f"  written      {', '.join(written)}")
    print("\n".join(answer_lines(answers)))
    return 0


def optional_outputs(result: Path) -> list[Path]:
    """The plot beside a result file. A failure here is a warning on stderr, never a
    failed run: the result file is already complete (status 'ok')."""
    from .plots import plot_result
    try:
        return [plot_result(result)]
    except Exception as exc:  # noqa: BLE001 - an optional output never fails a good run
        print(f"warning: the plot of {result} was not written: {type(exc).__name__}: {exc}",
              file=sys.stderr)
        return []


def stage_table(stages: dict[str, float]) -> str:
    """The per-stage summary of a luffing run as aligned text."""
    from .history import STAGES
    lines = ["  stage        t (s)            tip sag min..max (mm)"]
    for stage in STAGES:
        if f"{stage}_min" not in stages:
            continue
        lines.append(f"  {stage:12s} {stages[stage + '_t0']:6.3f}..{stages[stage + '_t1']:<7.3f}"
                     f"  {1e3 * stages[stage + '_min']:9.3f} .. {1e3 * stages[stage + '_max']:9.3f}")
    if "vibration_frequency_hz" in stages:
        lines.append(f"  vibration    {stages['vibration_frequency_hz']:.4f} Hz, amplitude "
                     f"{1e3 * stages['vibration_amplitude']:.4f} mm about "
                     f"{1e3 * stages['vibration_mean']:.3f} mm")
    return "\n".join(lines)


def _cmd_sweep(args: argparse.Namespace) -> int:
    from .sweep import SweepInterrupted, run_sweep, table_lines
    if args.workers is not None and args.scheduler:
        raise InputError("give --workers or --scheduler, not both")
    out = args.output or str(Path("results") / (Path(args.scene).stem + "_sweep"))
    if args.force:
        args.set = [*args.set, "scene.bounds=off"]
    try:
        rows = run_sweep(args.scene, args.vary, out, base=args.set, workers=args.workers,
                         scheduler=args.scheduler, reference=args.reference)
    except SweepInterrupted as stop:
        done = sum(r["status"] in ("ok", "failed", "unstable") for r in stop.rows)
        by = f" (stopped by {signal.Signals(stop.signum).name})" if stop.signum else ""
        print(f"ancf sweep: interrupted: {done} of {len(stop.rows)} cases finished, the "
              f"others cancelled; report in {out}/summary.md{by}", file=sys.stderr)
        return stop.exit_code
    keys = [v.split("=", 1)[0].strip().lower() for v in args.vary]
    print("\n".join(table_lines(rows, keys)))
    print(f"\nwritten {out}/summary.md, summary.csv, *.png and one .h5 per case")
    failed = [r for r in rows if r["status"] != "ok"]
    if failed:
        print(f"{len(failed)} case(s) failed; see {out}/summary.md", file=sys.stderr)
        return max(r["exit_code"] for r in failed)
    return 0


#: ``ancf info`` prints at most this many values of an array figure, then "... N more"
#: (the answers below the figures list every reaction, frequency and load factor)
INFO_ARRAY_VALUES = 8


def _info_value(value: object) -> object:
    """An array figure as text, cut after INFO_ARRAY_VALUES values with a mark."""
    import numpy as np
    if not isinstance(value, np.ndarray):
        return value
    flat = value.ravel()
    if flat.size <= INFO_ARRAY_VALUES:
        return np.array2string(value, precision=6, max_line_width=1 << 30)
    shown = np.array2string(flat[:INFO_ARRAY_VALUES], precision=6, max_line_width=1 << 30)
    return f"{shown[:-1]} ...] ... {flat.size - INFO_ARRAY_VALUES} more"


def json_ready(value: object) -> object:
    """A summary or answers value as plain JSON types (arrays as lists, whole)."""
    import numpy as np
    if isinstance(value, dict):
        return {str(k): json_ready(v) for k, v in value.items()}
    if isinstance(value, (list, tuple)):
        return [json_ready(v) for v in value]
    if isinstance(value, np.ndarray):
        return json_ready(value.tolist())
    if isinstance(value, np.generic):
        return value.item()
    if isinstance(value, bytes):
        return value.decode()
    return value


def _cmd_info(args: argparse.Namespace) -> int:
    """The verdict on the first line (ok, failed, interrupted, running, abandoned), then
    the main figures and the answers (every reaction, frequency and load factor); with
    --json one JSON object: file, verdict, detail, summary (every figure, arrays whole)
    and answers."""
    from .results.hdf5 import read_summary, verdict
    from .results.headline import answer_lines, read_answers
    path = Path(args.file)
    try:
        summary = read_summary(path)  # InputError (exit 2) when missing, not HDF5, not ours
        word, detail = verdict(path, summary)
        try:
            answers = read_answers(path)
        except (OSError, KeyError, ValueError):
            answers = {}  # a partial file (failed or interrupted): the figures are all
    except (AncfError, *PROGRAMMING_ERRORS):
        raise
    except Exception as exc:  # noqa: BLE001 - a damaged file: exit 2 naming it
        raise corrupted(path, exc) from None
    if args.json:
        import json
        print(json.dumps(json_ready({"file": str(path), "verdict": word, "detail": detail,
                                     "summary": summary, "answers": answers}), indent=1))
        return 0
    print(f"{path}: {word}: {detail}")
    skip = {"scene", "status", "message"}
    for key, value in summary.items():
        if key in skip or (isinstance(value, str) and not value):
            continue
        if isinstance(value, str) and "\n" in value:
            value = value.replace("\n", "; ")
        print(f"{key:32s} {_info_value(value)}")
    for line in answer_lines(answers):
        print(line)
    return 0


def _cmd_plot(args: argparse.Namespace) -> int:
    from .plots import plot_result, plot_results
    paths = [Path(f) for f in args.file]
    for path in paths:
        if not path.is_file():
            raise InputError("result file not found", file=str(path))
    try:
        png = plot_result(paths[0], args.output) if len(paths) == 1 else \
            plot_results(paths, args.output)
    except (ValueError, KeyError, OSError) as exc:
        raise InputError(str(exc), file=", ".join(map(str, paths))) from None
    except (AncfError, *PROGRAMMING_ERRORS):
        raise
    except Exception as exc:  # noqa: BLE001 - a damaged file: exit 2 naming it
        raise corrupted(", ".join(map(str, paths)), exc) from None
    print(f"written {png}")
    if len(paths) == 1:
        from .plots import plot_sections
        try:
            extra = plot_sections(paths[0], _sections_png(args.output, paths[0]))
        except (ValueError, KeyError, OSError):
            extra = None  # no section forces in the file: the main figure is all
        if extra is not None:
            print(f"written {extra}")
    return 0


def _cmd_show(args: argparse.Namespace) -> int:
    """The preview of a scene's undeformed model (:mod:`ancfdrv.preview`): nothing is
    solved, no result file is written."""
    from .preview import show_scene
    png = show_scene(args.scene, args.set, args.output)
    print(f"written {png}")
    return 0


def _cmd_animate(args: argparse.Namespace) -> int:
    """An animation of a dynamic run, or of a mode or buckling shape (:mod:`ancfdrv.animate`)."""
    from .animate import animate
    path = Path(args.file)
    if not path.is_file():
        raise InputError("result file not found", file=str(path))
    try:
        out = animate(path, args.output, mode=args.mode, view=args.view)
    except (KeyError, OSError) as exc:
        raise corrupted(path, exc) from None
    print(f"written {out}")
    return 0


def corrupted(path: object, exc: BaseException) -> InputError:
    """A result file that opens but whose content is damaged or not what a run writes."""
    text = str(exc).splitlines()[0][:200] if str(exc) else ""
    return InputError(f"cannot read it as an ancfdrv result file: damaged or not written by "
                      f"a run ({type(exc).__name__}{': ' + text if text else ''})",
                      file=str(path))


def _sections_png(output: str | None, h5_path: Path) -> Path:
    """Where the section-force figure goes: beside the main figure, suffix _sections."""
    base = Path(output) if output else h5_path.with_suffix(".png")
    return base.with_name(base.stem + "_sections.png")


def _run_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene")
    p.add_argument("-o", "--output", help="HDF5 result file (default from &output); never "
                   "an input file; refused while another run writes it")
    p.add_argument("--set", action="append", default=[], metavar="GROUP.KEY=VALUE",
                   help="override a namelist value (repeatable)")
    p.add_argument("--force", action="store_true", help="accept drives and loads beyond "
                   "their physical bounds (the same as --set scene.bounds=off)")
    p.add_argument("--plot", action="store_true", help="write the plot beside the result "
                   "(OUT.png; the same as output.plot = .true.; ancf plot draws any result "
                   "later)")
    p.set_defaults(func=_cmd_run)


def _sweep_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene")
    p.add_argument("--vary", action="append", required=True, metavar="GROUP.KEY=V1,V2,...")
    p.add_argument("--set", action="append", default=[], metavar="GROUP.KEY=VALUE")
    p.add_argument("--force", action="store_true", help="accept drives and loads beyond "
                   "their physical bounds (the same as --set scene.bounds=off)")
    p.add_argument("-o", "--output", help="output directory")
    p.add_argument("--workers", type=int, help="parallel processes (default: all cores; "
                   "at most one per core, per case and per 150 MB of available memory)")
    p.add_argument("--scheduler", help="address of a Dask distributed scheduler")
    p.add_argument("--reference", metavar="REF.h5", help="a result file every case is also "
                   "compared with (column 'err vs reference'; the error-against-time chart "
                   "shows it): e.g. a converged model of another formulation")
    p.set_defaults(func=_cmd_sweep)


def _info_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file")
    p.add_argument("--json", action="store_true", help="write the figures and the answers "
                   "as one JSON object (every reaction, frequency and load factor; arrays "
                   "whole)")
    p.set_defaults(func=_cmd_info)


def _plot_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file", nargs="+", help="HDF5 result file; several only for leaf spring "
                   "runs (kind 'spring'), e.g. prestress on and off")
    p.add_argument("-o", "--output", help="PNG file (default: beside the (first) HDF5, "
                   "<first>_compare.png for several)")
    p.set_defaults(func=_cmd_plot)


def _show_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("scene")
    p.add_argument("-o", "--output", help="PNG file (default: SCENE.png beside the scene)")
    p.add_argument("--set", action="append", default=[], metavar="GROUP.KEY=VALUE",
                   help="override a namelist value (repeatable)")
    p.set_defaults(func=_cmd_show)


def _animate_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("file")
    p.add_argument("-o", "--output", help="a .gif or .mp4 (default: beside the file; MP4 "
                   "when ffmpeg is installed, else GIF)")
    p.add_argument("--mode", type=int, help="animate mode N (1-based) of the file's modal or "
                   "buckling analysis")
    p.add_argument("--view", default="auto", choices=["auto", "xy", "yz", "zx"],
                   help="the plane drawn (default: the mesh's two largest extents)")
    p.set_defaults(func=_cmd_animate)


#: each command: the options of its parser (help, epilog) and what adds its arguments
_COMMANDS = {
    "run": (dict(help="run one scene", epilog=EXIT_CODES,
                 formatter_class=argparse.RawDescriptionHelpFormatter), _run_arguments),
    "sweep": (dict(help="run every combination of --vary values"), _sweep_arguments),
    "info": (dict(help="summarize a result file; the first line says whether the run "
                  "finished (ok), failed, was interrupted, is running or was abandoned "
                  "(its writer was killed)"), _info_arguments),
    "plot": (dict(help="plot a result file (several: leaf spring runs overlaid)"),
             _plot_arguments),
    "show": (dict(help="draw the model of a scene before any solve: three views and an "
                  "isometric one with the names of bodies, joints, loads and probes "
                  "(nothing is solved)"), _show_arguments),
    "animate": (dict(help="animate a result: the whole mesh through a dynamic run, or a "
                     "mode or buckling shape (--mode N) oscillating"), _animate_arguments),
}


def _named_command(argv: list[str]) -> str | None:
    """The command a command line names: its first word that is not an option (only flags
    come before the command); None when there is none or it is no command (argparse then
    says so)."""
    for word in argv:
        if not word.startswith("-"):
            return word if word in _COMMANDS else None
    return None


def build_parser(command: str | None = None) -> argparse.ArgumentParser:
    """The ``ancf`` parser. ``command``: the command the line names (:func:`_named_command`):
    only its arguments are added, the other commands listed with their help as ``ancf
    --help`` shows them (building every command's arguments was ~13 M instructions of
    each command's start); None: every command's."""
    parser = argparse.ArgumentParser(prog="ancf", description="ANCF flexible multibody "
                                     "simulations from Fortran namelist scenes",
                                     epilog=EXIT_CODES,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--version", action="version", version=f"ancf (ancfdrv) {__version__}")
    parser.add_argument("--debug", action="store_true",
                        help="print the full trace of an internal error (exit status 1)")
    sub = parser.add_subparsers(dest="command", required=True)
    for name, (options, arguments) in _COMMANDS.items():
        p = sub.add_parser(name, **options)
        if command is None or command == name:
            arguments(p)
    return parser


def _trace_file(command: str) -> Path:
    """Write the current exception's trace to a new file in the temporary directory."""
    import tempfile
    stamp = _dt.datetime.now().strftime("%Y%m%d-%H%M%S")
    fd, name = tempfile.mkstemp(prefix=f"ancf-{command}-{stamp}-", suffix=".trace.txt")
    with os.fdopen(fd, "w") as f:
        f.write(f"ancfdrv {__version__}, python {sys.version.split()[0]}\n")
        f.write(f"command: {' '.join(sys.argv)}\n\n")
        f.write(traceback.format_exc())
    return Path(name)


def _internal_error(command: str, exc: BaseException, debug: bool) -> int:
    if debug:
        traceback.print_exc()
        return 1
    summary = f"{type(exc).__name__}: {exc}".splitlines()[0] if str(exc) else type(exc).__name__
    try:
        where = f"full trace in {_trace_file(command)}"
    except OSError:
        where = "the trace could not be written"
    print(f"ancf {command}: internal error: {summary} ({where}; run with --debug to see it)",
          file=sys.stderr)
    return 1


_COMMAND_PID = os.getpid()


def _terminate(signum: int, frame: object) -> None:
    """SIGTERM outside a run: end the command with one line (exit 143). A process forked
    from the command (a sweep's worker) inherits this handler: it dies as by default."""
    if os.getpid() != _COMMAND_PID:
        signal.signal(signum, signal.SIG_DFL)
        os.kill(os.getpid(), signum)
        return
    raise Interrupted("terminated by SIGTERM", signum=signum)


def main(argv: list[str] | None = None) -> int:
    """The ``ancf`` command; returns the exit status (see the module docstring)."""
    words = sys.argv[1:] if argv is None else argv
    args = build_parser(_named_command(words)).parse_args(words)
    command = args.command
    from .io.safe_write import ignore_file_size_signal
    if threading.current_thread() is threading.main_thread():
        ignore_file_size_signal()  # beyond ulimit -f a write fails (exit 3), no SIGXFSZ
    # SIGTERM outside a run (which handles it itself) ends the command without a trace
    global _COMMAND_PID
    previous = None
    if threading.current_thread() is threading.main_thread():
        _COMMAND_PID = os.getpid()
        previous = signal.signal(signal.SIGTERM, _terminate)
    try:
        return args.func(args)
    except Interrupted as exc:
        print(f"ancf {command}: {exc}", file=sys.stderr)
        return exc.exit_code
    except AncfError as exc:
        print(f"ancf {command}: error: {exc}", file=sys.stderr)
        return exc.exit_code
    except KeyboardInterrupt:
        print(f"ancf {command}: interrupted", file=sys.stderr)
        return 130
    except BrokenPipeError:  # the reader of our output went away (ancf info F | head -1)
        try:
            os.dup2(os.open(os.devnull, os.O_WRONLY), sys.stdout.fileno())
        except OSError:
            pass
        return 128 + signal.SIGPIPE
    except OSError as exc:
        from .io.safe_write import disk_full
        if not disk_full(exc):
            return _internal_error(command, exc, args.debug)
        print(f"ancf {command}: error: cannot write: the disk or the file-size limit is full "
              f"({str(exc).splitlines()[0][:200]})", file=sys.stderr)
        return 3
    except Exception as exc:  # noqa: BLE001 - a bug: one line, the trace in a file
        return _internal_error(command, exc, args.debug)
    finally:
        if previous is not None:
            signal.signal(signal.SIGTERM, previous)


if __name__ == "__main__":
    sys.exit(main())
