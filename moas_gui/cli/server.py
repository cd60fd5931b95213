"""``moas-server``: the MOAS II server (``--check FILE`` checks a configuration)."""

from __future__ import annotations

import argparse
import sys

from moas_gui import __version__


def _parser() -> argparse.ArgumentParser:
    parser = argparse.ArgumentParser(
        prog="moas-server",
        description="The MOAS II antenna switch server. With FILE, opens that configuration.")
    parser.add_argument("file", nargs="?", help="a .moas configuration file")
    parser.add_argument("--check", action="store_true",
                        help="check FILE, print every problem (or a summary) and exit; "
                             "exit status 0 only when the file is usable")
    parser.add_argument("--headless", action="store_true",
                        help="run without a window, logging to standard error")
    parser.add_argument("--version", action="version", version=f"moas-server {__version__}")
    return parser


def check(path: str) -> int:
    """Print the problems of ``path`` (or its summary); 0 when it is usable."""
    from moas_gui.engine.config import load_config
    from moas_gui.engine.config.summary import summarize

    result = load_config(path)
    for problem in result.problems:
        print(problem)
    if result.config is None:
        count = len(result.errors)
        print(f"{path}: {count} error{'s' if count != 1 else ''}; the configuration cannot be used.")
        return 1
    if result.warnings:
        print()
    print(summarize(result.config))
    return 0


def main(argv: list[str] | None = None) -> int:
    args = _parser().parse_args(argv)
    if args.check:
        if not args.file:
            print("moas-server: --check needs a configuration file", file=sys.stderr)
            return 2
        return check(args.file)
    print("moas-server: the server itself is not built yet; use --check FILE to check a "
          "configuration.", file=sys.stderr)
    return 2


if __name__ == "__main__":
    sys.exit(main())
