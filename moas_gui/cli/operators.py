"""``moas-server --add-operator / --remove-operator / --list-operators``.

``--add-operator NAME --role ROLE [--radios 1/1,1/2]`` prints what was made, then the
token alone on the last line of standard output (shown this once: only its hash is
kept).  ``--remove-operator NAME`` also tells a running server, through the
single-instance channel, which ends that operator's sessions at once.  A server the
channel cannot reach (one started with ``--new-instance``, or this launch's own
``--new-instance``) notices the file's change itself within a second and ends them
then; the command says which happened.
"""

from __future__ import annotations

import argparse
import sys

from moas_gui.operators import OperatorBook, OperatorError, Role, parse_radios


def operators_command(args: argparse.Namespace, instance_name: str) -> int:
    book = OperatorBook()
    try:
        if args.list_operators:
            return _list(book)
        if args.add_operator:
            return _add(book, args)
        return _remove(book, args.remove_operator, instance_name, args.new_instance)
    except OperatorError as exc:
        print(f"moas-server: {exc}", file=sys.stderr)
        return 1
    except OSError as exc:
        print(f"moas-server: cannot write {book.path}: {exc.strerror or exc}", file=sys.stderr)
        return 1


def _list(book: OperatorBook) -> int:
    operators = book.operators()
    if not operators:
        print(f"No operators ({book.path} holds none): the LAN is open to every client, "
              "and nothing outside it gets in.")
        return 0
    for op in operators:
        print(f"{op.name}\t{op.role.value}\t{op.radios_text()}")
    return 0


def _add(book: OperatorBook, args: argparse.Namespace) -> int:
    if args.role is None:
        print("moas-server: --add-operator needs --role view, operate or admin", file=sys.stderr)
        return 2
    radios = parse_radios(args.radios) if args.radios else None
    operator, token = book.add(args.add_operator, Role(args.role), radios,
                               ag_code=args.ag_code)
    print(f'Operator "{operator.name}" ({operator.role.value}, {operator.radios_text()}) '
          f"added to {book.path}.")
    print("Its token follows, shown this once (only its hash is kept); give it to the "
          "operator's client:")
    print(token)
    return 0


_NOTICES = ("a server running with this operators file (one started with --new-instance "
            "too) notices the change itself and ends that operator's sessions within a "
            "second")


def _remove(book: OperatorBook, name: str, instance_name: str, alone: bool) -> int:
    operator = book.remove(name)
    print(f'Operator "{operator.name}" removed from {book.path}.')
    if alone:
        print(f"No running server was told (--new-instance); {_NOTICES}.")
        return 0
    from moas_gui.single_instance import InstanceError, offer

    try:
        answer = offer(instance_name, None, {"command": "remove_operator",
                                             "name": operator.name}, timeout=5.0)
    except (InstanceError, OSError):  # no instance directory: nothing runs
        answer = None
    if answer is not None and answer.done is not None:
        print(f"The running server: {answer.done}.")
    elif answer is not None and answer.running:
        print(f"A server is running but did not answer; {_NOTICES}.", file=sys.stderr)
    else:
        print(f"No running server could be reached through the single-instance channel; "
              f"{_NOTICES}.")
    return 0


__all__ = ["operators_command"]
