"""The station's operators: who may act over the network, with which role and radios.

An operator is a name, a :class:`Role` and, optionally, the radios it may act on
(none given: every radio).  Each has one token, made by :func:`OperatorBook.add`,
shown once and never stored: the book keeps a salted scrypt hash of it, in
``operators.json`` in the configuration directory (:func:`moas_gui.places.config_dir`),
written atomically and readable by the user alone.

A token reads ``moas1.<id>.<secret>``: the id (8 hex digits, not secret) finds the
one operator whose hash is checked, so a hello costs one hash however many operators
there are; the secret is 32 random bytes (URL-safe base64), so a guess is hopeless
and a fast hash would do -- scrypt is used anyway, with small parameters.  The check
compares in constant time, and an id no operator has costs the same hash (against a
dummy), so the time a check takes does not tell whether an id exists.  Nothing here
logs a token.

The file is read as the saved state is: a regular file only (a FIFO, a device or a
directory there is refused, never waited on), at most :data:`MAX_FILE_BYTES`, and
kept in memory until its modification time, size or inode changes (one ``stat`` per
check).  The checks hash (a few ms each): the server runs them, and so every read of
the file, on its one secret-check thread (:mod:`moas_gui.net.secrets`), never on
its event loop.

Roles (what :mod:`moas_gui.net.identity` enforces):

* ``view`` sees everything and changes nothing;
* ``operate`` selects, steps and tunes its radios, sets their transmit and receive
  focus, runs functions whose radios are all its own, and turns the rotators of the
  antennas its radios use;
* ``admin`` may also stop, start and reset the switches, and act on any radio.
"""

from __future__ import annotations

import base64
import hashlib
import hmac
import json
import os
import re
import secrets
import stat
import sys
import threading
from dataclasses import dataclass, replace
from enum import StrEnum
from pathlib import Path
from typing import Any, Final

from moas_gui.errors import MoasError
from moas_gui.files import write_atomic
from moas_gui.places import config_dir, state_dir

FILE_NAME: Final = "operators.json"
KNOWN_DEVICES_FILE: Final = "known-devices.json"
"""In the state directory: the addresses each operator has signed in from (a guesser's
failures never hold those back, docs/security.md), kept across restarts."""
MAX_KNOWN_DEVICES: Final = 4096
TOKEN_PREFIX: Final = "moas1"
_SCRYPT = {"n": 1 << 12, "r": 8, "p": 1, "dklen": 32}
"""Cheap enough for every hello (a few ms), ample for 256-bit random secrets."""
_NAME = re.compile(r"^[A-Za-z0-9][A-Za-z0-9 ._@-]{0,39}$")
MAX_OPERATORS: Final = 1000
MAX_FILE_BYTES: Final = 2 << 20
"""The largest operators file read: :data:`MAX_OPERATORS` entries take under 500 kB."""
AG_CODE_DIGITS: Final = (6, 9)
"""An Antenna Genius code's least and most digits (``--add-operator --ag-code``)."""
_DUMMY_SALT: Final = bytes(16)

RadioRef = tuple[int, int]


class Role(StrEnum):
    VIEW = "view"
    OPERATE = "operate"
    ADMIN = "admin"


class OperatorError(MoasError, ValueError):
    """A request about operators that cannot be done; the message says why."""


@dataclass(frozen=True, slots=True)
class Operator:
    """One operator as the book holds it (no token, only its hash)."""

    name: str
    role: Role
    radios: frozenset[RadioRef] | None = None
    """The radios it may act on; None: every radio."""
    key: str = ""
    """The token's public id."""
    salt: str = ""
    digest: str = ""
    ag_salt: str = ""
    ag_digest: str = ""
    """The hash of its Antenna Genius code (``--ag-code``; empty: none): AG clients
    authenticate with a number (``auth code=N``), not a token."""

    def radios_text(self) -> str:
        if self.radios is None:
            return "all radios"
        return ",".join(f"{s}/{r}" for s, r in sorted(self.radios))

    def to_json(self) -> dict[str, Any]:
        return {"name": self.name, "role": self.role.value,
                "radios": None if self.radios is None else sorted(list(r) for r in self.radios),
                "key": self.key, "salt": self.salt, "hash": self.digest,
                **({"ag_salt": self.ag_salt, "ag_hash": self.ag_digest} if self.ag_digest
                   else {})}


def parse_radios(text: str) -> frozenset[RadioRef]:
    """``"1/1,1/2"`` to radios; :class:`OperatorError` naming the part that is not one."""
    radios: set[RadioRef] = set()
    for part in text.split(","):
        part = part.strip()
        match = re.fullmatch(r"(\d{1,9})/(\d{1,9})", part)
        if match is None:
            raise OperatorError(f"{part!r} is not a radio: write STATION/RADIO, as in 1/2")
        radios.add((int(match[1]), int(match[2])))
    return frozenset(radios)


def check_name(name: str) -> str:
    if not _NAME.match(name):
        raise OperatorError(
            f"{name!r} is not an operator name: 1 to 40 letters, digits, spaces or . _ @ -, "
            "starting with a letter or digit")
    return name


def _hash(secret: str, salt: bytes) -> bytes:
    return hashlib.scrypt(secret.encode("utf-8"), salt=salt, **_SCRYPT)


def split_token(token: str) -> tuple[str, str] | None:
    """``(id, secret)`` of a token in the book's form, or None."""
    parts = token.strip().split(".")
    if len(parts) != 3 or parts[0] != TOKEN_PREFIX or not re.fullmatch(r"[0-9a-f]{8}", parts[1]):
        return None
    if not 20 <= len(parts[2]) <= 100:
        return None
    return parts[1], parts[2]


def _from_json(item: Any) -> Operator:
    if not isinstance(item, dict):
        raise OperatorError("an entry is not an object")
    radios = item.get("radios")
    return Operator(
        check_name(str(item["name"])), Role(item["role"]),
        None if radios is None else frozenset((int(s), int(r)) for s, r in radios),
        str(item["key"]), str(item["salt"]), str(item["hash"]),
        str(item.get("ag_salt", "")), str(item.get("ag_hash", "")))


def _kind_of(mode: int) -> str:
    kinds = ((stat.S_ISFIFO, "a FIFO (named pipe)"), (stat.S_ISCHR, "a character device"),
             (stat.S_ISBLK, "a block device"), (stat.S_ISSOCK, "a socket"),
             (stat.S_ISDIR, "a directory"))
    return next((words for test, words in kinds if test(mode)), "not a regular file")


Signature = tuple[int, int, int, int]
"""What tells one version of the file from another: (mtime ns, size, inode, device)."""


def file_signature(path: Path) -> Signature | None:
    """The file's :data:`Signature` now (one ``stat``, which never waits on a FIFO), or
    None when there is none."""
    try:
        info = os.stat(path)
    except OSError:
        return None
    return (info.st_mtime_ns, info.st_size, info.st_ino, info.st_dev)


def read_operators_file(path: Path, limit: int = MAX_FILE_BYTES) -> bytes | None:
    """The file's bytes, or None when there is none; :class:`OperatorError` naming the
    file for anything that is not a regular file of at most ``limit`` bytes.  Opening
    never waits (a FIFO with no writer would block for ever) and no more than ``limit``
    bytes are read.  (The known devices' file is read the same way.)"""
    try:
        fd = os.open(path, os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0))
    except FileNotFoundError:
        return None
    except OSError as exc:
        raise OperatorError(f"cannot read {path}: {exc.strerror or exc}") from None
    with os.fdopen(fd, "rb") as opened:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise OperatorError(f"cannot read {path}: it is {_kind_of(info.st_mode)}, not a "
                                "regular file")
        if info.st_size > limit:
            raise OperatorError(f"cannot read {path}: it holds {info.st_size:,} bytes, more "
                                f"than an operators file ever does (at most {limit:,})")
        data = opened.read(limit + 1)
    if len(data) > limit:
        raise OperatorError(f"cannot read {path}: it holds more than {limit:,} bytes")
    return data


class OperatorBook:
    """The operators file, read again whenever it changed (its :data:`Signature`), so
    that a second process (``moas-server --add-operator`` beside a running server) is
    seen at the next check.  Safe to use from two threads."""

    def __init__(self, path: Path | None = None) -> None:
        self.path = path if path is not None else config_dir() / FILE_NAME
        self._lock = threading.Lock()
        self._cached: tuple[Signature | None, tuple[Operator, ...] | OperatorError] | None = None

    def operators(self) -> tuple[Operator, ...]:
        """Every operator, in the file's order; none when there is no file.  A file that
        cannot be read raises :class:`OperatorError` saying where and why.  Read from
        the disk only when it changed since the last call."""
        with self._lock:
            signature = file_signature(self.path)
            cached = self._cached
            if cached is None or cached[0] != signature or signature is None:
                cached = self._cached = (signature, self._load())
        if isinstance(cached[1], OperatorError):
            raise cached[1]
        return cached[1]

    def cached(self) -> tuple[Operator, ...]:
        """The operators as last read (no file access: for the event loop); none before
        the first read or while the file cannot be read."""
        cached = self._cached
        return () if cached is None or isinstance(cached[1], OperatorError) else cached[1]

    def _load(self) -> tuple[Operator, ...] | OperatorError:
        try:
            data = read_operators_file(self.path)
        except OperatorError as exc:
            return exc
        if data is None:
            return ()
        try:
            entries = json.loads(data)["operators"]
            return tuple(_from_json(item) for item in entries)
        except (ValueError, KeyError, TypeError) as exc:
            return OperatorError(f"{self.path} is not an operators file: {exc}")

    def _write(self, operators: tuple[Operator, ...]) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        text = json.dumps({"operators": [op.to_json() for op in operators]}, indent=1)
        if not self.path.exists():  # the first one: made private before anything is in it
            fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            os.close(fd)
        write_atomic(self.path, text.encode("utf-8"))
        if sys.platform != "win32":
            os.chmod(self.path, 0o600)

    def add(self, name: str, role: Role, radios: frozenset[RadioRef] | None = None,
            ag_code: str | None = None) -> tuple[Operator, str]:
        """A new operator and its token (to be shown once; only its hash is kept), with
        an Antenna Genius code when ``ag_code`` is given (also kept as a hash only)."""
        check_name(name)
        existing = self.operators()
        if ag_code is not None:
            check_ag_code(ag_code)
            if self.check_ag_code(ag_code) is not None:
                raise OperatorError("another operator has that Antenna Genius code")
        if any(op.name.lower() == name.lower() for op in existing):
            raise OperatorError(f"there is already an operator {name!r} "
                                "(remove it first to give it a new token)")
        if len(existing) >= MAX_OPERATORS:
            raise OperatorError(f"the station already has {MAX_OPERATORS} operators")
        keys = {op.key for op in existing}
        key = secrets.token_hex(4)
        while key in keys:
            key = secrets.token_hex(4)
        secret = base64.urlsafe_b64encode(secrets.token_bytes(32)).decode().rstrip("=")
        salt = secrets.token_bytes(16)
        operator = Operator(name, role, radios, key, salt.hex(), _hash(secret, salt).hex())
        if ag_code is not None:
            ag_salt = secrets.token_bytes(16)
            operator = replace(operator, ag_salt=ag_salt.hex(),
                               ag_digest=_hash(ag_code, ag_salt).hex())
        self._write((*existing, operator))
        return operator, f"{TOKEN_PREFIX}.{key}.{secret}"

    def remove(self, name: str) -> Operator:
        existing = self.operators()
        for op in existing:
            if op.name.lower() == name.lower():
                self._write(tuple(o for o in existing if o is not op))
                return op
        raise OperatorError(f"there is no operator {name!r}")

    def find(self, name: str) -> Operator | None:
        return next((op for op in self.operators() if op.name.lower() == name.lower()), None)

    def check(self, token: str) -> Operator | None:
        """The operator whose token this is, or None (a wrong or malformed token)."""
        parts = split_token(token)
        if parts is None:
            return None
        key, secret = parts
        try:
            found = next((op for op in self.operators() if op.key == key), None)
        except OperatorError:
            found = None
        if found is None:  # the same hash against nothing: an unknown id takes as long
            hmac.compare_digest(_hash(secret, _DUMMY_SALT).hex(), "0" * 64)
            return None
        if hmac.compare_digest(_hash(secret, bytes.fromhex(found.salt)).hex(), found.digest):
            return found
        return None

    def key_of(self, token: str) -> str | None:
        """The id a token names (whether or not an operator has it), or None."""
        parts = split_token(token)
        return None if parts is None else parts[0]

    def check_ag_code(self, code: str) -> Operator | None:
        """The operator whose Antenna Genius code this is, or None."""
        code = code.strip()
        if not code.isdigit():
            return None
        try:
            operators = self.operators()
        except OperatorError:
            return None
        for op in operators:
            if op.ag_digest and hmac.compare_digest(
                    _hash(code, bytes.fromhex(op.ag_salt)).hex(), op.ag_digest):
                return op
        return None


Device = tuple[str, str]
"""An address (as the failure budgets count it) and an operator's name in lower case."""


class KnownDevices:
    """The file of known devices (:data:`KNOWN_DEVICES_FILE`): at most
    :data:`MAX_KNOWN_DEVICES` pairs, the newest last; read and written by the secret
    checks' worker, never the event loop.  A file that cannot be read counts as empty
    (the server says so once) -- the devices are then known again at their next
    sign-in."""

    def __init__(self, path: Path | None = None) -> None:
        self.path = path if path is not None else state_dir() / KNOWN_DEVICES_FILE

    def load(self) -> list[Device]:
        data = read_operators_file(self.path, MAX_FILE_BYTES // 4)
        if data is None:
            return []
        try:
            pairs = json.loads(data)["devices"]
            return [(str(a), str(n).lower()) for a, n in pairs][-MAX_KNOWN_DEVICES:]
        except (ValueError, KeyError, TypeError) as exc:
            raise OperatorError(f"{self.path} is not a file of known devices: {exc}") from None

    def save(self, devices: list[Device]) -> None:
        self.path.parent.mkdir(parents=True, exist_ok=True)
        text = json.dumps({"devices": [list(d) for d in devices[-MAX_KNOWN_DEVICES:]]})
        if not self.path.exists():  # made private before anything is in it
            fd = os.open(self.path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600)
            os.close(fd)
        write_atomic(self.path, text.encode("utf-8"))
        if sys.platform != "win32":
            os.chmod(self.path, 0o600)


def check_ag_code(code: str) -> str:
    """A new Antenna Genius code: 6 to 9 digits (AG clients send a number; fewer could
    be guessed in a contest weekend, docs/security.md); else :class:`OperatorError`
    saying so."""
    least, most = AG_CODE_DIGITS
    if not (code.isdigit() and least <= len(code) <= most):
        why = (f"{len(code)} digits are too few to resist guessing" if code.isdigit()
               and len(code) < least else "it must be digits only")
        raise OperatorError(f"an Antenna Genius code is {least} to {most} digits, not "
                            f"{code!r}: {why}")
    return code


__all__ = [
    "AG_CODE_DIGITS",
    "FILE_NAME",
    "KNOWN_DEVICES_FILE",
    "MAX_FILE_BYTES",
    "MAX_KNOWN_DEVICES",
    "MAX_OPERATORS",
    "Device",
    "KnownDevices",
    "Operator",
    "OperatorBook",
    "OperatorError",
    "Role",
    "check_ag_code",
    "check_name",
    "file_signature",
    "parse_radios",
    "read_operators_file",
    "split_token",
]
