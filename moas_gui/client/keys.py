"""What the desktop client keeps per server: its operator's token and its pinned fingerprint.

The token is a secret: it goes to the system's keyring (the ``keyring`` package:
Secret Service on Linux, the Keychain on macOS, the Credential Manager on Windows),
under the service ``moas-gui`` and the user ``token:HOST:PORT``.  Where no keyring
service runs (a Pi without a desktop session, CI), it goes to ``client-tokens.json``
in the configuration directory (:func:`moas_gui.places.config_dir`), a file readable
by the user alone.  The fingerprint pinned on first use is no secret: it is kept in
``known-servers.json`` beside it.
"""

from __future__ import annotations

import contextlib
import json
import logging
import os
import sys
from pathlib import Path
from typing import Final

from moas_gui.files import write_atomic
from moas_gui.places import config_dir

log = logging.getLogger(__name__)

SERVICE: Final = "moas-gui"
TOKENS_FILE: Final = "client-tokens.json"
KNOWN_FILE: Final = "known-servers.json"


def _keyring_usable() -> bool:
    try:
        import keyring
        from keyring.backends.fail import Keyring as Failing
    except ImportError:
        return False
    try:
        backend = keyring.get_keyring()
    except Exception:  # noqa: BLE001 - a broken keyring set-up is the same as none
        return False
    if isinstance(backend, Failing) or getattr(backend, "priority", 1) <= 0:
        return False
    # keyrings.alt's file keyrings (a test dependency) are no system keyring: a plaintext
    # one in the home directory is worse than this module's own private file
    return not type(backend).__module__.startswith("keyrings.alt")


def _read(path: Path) -> dict[str, str]:
    try:
        data = json.loads(path.read_text(encoding="utf-8"))
    except (OSError, ValueError):
        return {}
    return {str(k): str(v) for k, v in data.items()} if isinstance(data, dict) else {}


def _write_private(path: Path, data: dict[str, str]) -> None:
    path.parent.mkdir(parents=True, exist_ok=True)
    if not path.exists():
        os.close(os.open(path, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
    write_atomic(path, json.dumps(data, indent=1).encode("utf-8"))
    if sys.platform != "win32":
        os.chmod(path, 0o600)


class ClientKeys:
    """Tokens and pins of the servers this user's client talks to."""

    def __init__(self, directory: Path | None = None, *, use_keyring: bool | None = None) -> None:
        self.directory = directory if directory is not None else config_dir()
        self.use_keyring = _keyring_usable() if use_keyring is None else use_keyring

    @staticmethod
    def _user(server: str) -> str:
        return f"token:{server}"

    def token(self, server: str) -> str | None:
        if self.use_keyring:
            import keyring

            with contextlib.suppress(Exception):
                found = keyring.get_password(SERVICE, self._user(server))
                if found:
                    return str(found)
        return _read(self.directory / TOKENS_FILE).get(server)

    def set_token(self, server: str, token: str) -> str:
        """Keeps ``token`` for ``server``; returns where (for the user to be told)."""
        if self.use_keyring:
            import keyring

            try:
                keyring.set_password(SERVICE, self._user(server), token)
                return "the system keyring"
            except Exception as exc:  # noqa: BLE001 - fall back to the private file
                log.warning("The system keyring refused the token (%s); keeping it in a "
                            "file readable by this user alone", type(exc).__name__)
        path = self.directory / TOKENS_FILE
        data = _read(path)
        data[server] = token
        _write_private(path, data)
        return str(path)

    def forget_token(self, server: str) -> bool:
        """Forgets the token kept for ``server`` (keyring and file); True when one was."""
        forgot = False
        if self.use_keyring:
            import keyring

            with contextlib.suppress(Exception):  # none kept there: nothing to delete
                keyring.delete_password(SERVICE, self._user(server))
                forgot = True
        path = self.directory / TOKENS_FILE
        data = _read(path)
        if data.pop(server, None) is not None:
            _write_private(path, data)
            forgot = True
        return forgot

    def pin(self, server: str) -> str | None:
        return _read(self.directory / KNOWN_FILE).get(server)

    def set_pin(self, server: str, fingerprint: str) -> None:
        path = self.directory / KNOWN_FILE
        data = _read(path)
        data[server] = fingerprint
        _write_private(path, data)


__all__ = ["KNOWN_FILE", "SERVICE", "TOKENS_FILE", "ClientKeys"]
