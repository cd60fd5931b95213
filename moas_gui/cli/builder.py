"""The station builder's options of ``moas-server``: ``--what-if`` (the engine's answers
for a draft, printed) and ``--edit`` (the builder's window on a file).

``--what-if FILE --radio S/R --khz F [--radio S/R --khz F ...] [--transmitting S/R]
[--json]`` builds a fresh engine from FILE (never a running server's), tunes each
``--radio`` to the ``--khz`` given with it, in order, keys each ``--transmitting``
radio, and prints every radio's transmit, receive and alternate antenna and why.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path


def add_arguments(parser: argparse.ArgumentParser) -> None:
    parser.add_argument("--what-if", metavar="FILE",
                        help="print what the engine would choose for FILE's station with "
                             "the radios of --radio on the frequencies of --khz (and those "
                             "of --transmitting keyed): each radio's transmit, receive and "
                             "alternate antenna and why; --json for JSON")
    parser.add_argument("--radio", action="append", metavar="S/R",
                        help="with --what-if: a radio (station/radio) to tune to the --khz "
                             "given after it; repeat for more radios")
    parser.add_argument("--khz", action="append", metavar="F",
                        help="with --what-if: the frequency in kHz of the --radio before it")
    parser.add_argument("--transmitting", action="append", metavar="S/R",
                        help="with --what-if: a radio that transmits; may be repeated")
    parser.add_argument("--edit", metavar="FILE",
                        help="open the station builder on FILE (a file that does not exist "
                             "starts a new station with a short guide)")


def wants_builder(args: argparse.Namespace) -> bool:
    """Whether the command line asks for the builder or for what-if."""
    return bool(args.edit or args.what_if or args.radio or args.khz or args.transmitting)


def builder_command(args: argparse.Namespace) -> int:
    """``--edit`` or ``--what-if``: the exit status."""
    if args.edit and not args.what_if:
        return edit_command(args)
    return what_if_command(args)


def edit_command(args: argparse.Namespace) -> int:
    """``--edit FILE``: the builder's window, until it is closed."""
    from moas_gui.ui.display import NO_DISPLAY_ADVICE, display_problem

    problem = display_problem()
    if problem is not None:
        print(f"moas-server: {problem}; {NO_DISPLAY_ADVICE}", file=sys.stderr)
        return 1
    from moas_gui.builder.claims import FileClaimed, holder

    held = holder(Path(args.edit))
    if held is not None:  # refused at once, before the window's libraries are loaded
        print(f"moas-server: {FileClaimed(held)}", file=sys.stderr)
        return 1
    from moas_gui.cli.builder_restart import ask_to_restart
    from moas_gui.ui.builder_window import run_builder

    return run_builder(args.edit, ask_to_restart)


def what_if_command(args: argparse.Namespace) -> int:
    """``--what-if``: 0 with the answers printed, 1 for a file that cannot be used, 2 for
    options that do not go together."""
    from moas_gui.builder.whatif import (
        WhatIfError,
        answers_json,
        answers_text,
        parse_khz,
        parse_radio,
        what_if,
    )
    from moas_gui.config import load_config

    def refuse(message: str) -> int:
        print(f"moas-server: {message}", file=sys.stderr)
        return 2

    if not args.what_if:
        return refuse("--radio, --khz and --transmitting go with --what-if FILE")
    radios, khz = args.radio or [], args.khz or []
    if len(radios) != len(khz):
        return refuse(f"--what-if: each --radio needs its --khz ({len(radios)} --radio, "
                      f"{len(khz)} --khz)")
    if args.plan or args.plan_khz or args.check:
        return refuse("--what-if goes with neither --plan nor --check")
    try:
        tunings = [(parse_radio(r), parse_khz(k)) for r, k in zip(radios, khz, strict=True)]
        keyed = [parse_radio(r) for r in args.transmitting or []]
    except WhatIfError as exc:
        return refuse(f"--what-if: {exc}")
    result = load_config(args.what_if)
    if result.config is None:
        for problem in result.problems:
            print(problem, file=sys.stderr)
        print(f"{args.what_if}: the configuration cannot be used.", file=sys.stderr)
        return 1
    try:
        answers = what_if(result.config, tunings, keyed)
    except WhatIfError as exc:
        print(f"moas-server: --what-if: {args.what_if}: {exc}", file=sys.stderr)
        return 1
    sys.stdout.write(answers_json(args.what_if, answers) if args.json else answers_text(answers))
    return 0


__all__ = ["add_arguments", "builder_command", "edit_command", "wants_builder", "what_if_command"]
