"""Who may use the Antenna Genius front, and whether they must authenticate.

The AG protocol has no TLS: it is served only to loopback and the ``ClientAllow``
networks, never beyond.  Everything the front asks about access goes through one
:class:`AgAccess`, so that the server's one access policy (operators, tokens,
``--require-token``) can take its place whole:

* :meth:`~AgAccess.allowed` -- one call when a connection is accepted: None (it may
  stay) or why it is refused (an address outside ``ClientAllow``);
* :attr:`~AgAccess.admission` -- the pool the front's listener admits connections
  to: the program's one admission policy (:mod:`moas_gui.edge.admission`: caps per
  address and in total, the fair share, the reserve before a first command);
* :meth:`~AgAccess.needs_token` -- whether that peer gets ``V... AG AUTH`` and must send
  ``auth code=N`` before anything else;
* :meth:`~AgAccess.check_code` -- the operator an ``auth`` code stands for, or why not,
  from the server's one secret check (:class:`~moas_gui.net.secrets.SecretGuard`: off
  the loop, failures budgeted per address -- an IPv6 /64 being one -- and per operator
  from every address together, with a back-off that grows per failure, asked at every
  ``auth``, open sessions included);
* :meth:`~AgAccess.waiting` -- at accept: seconds an address must still wait after
  too many wrong codes (0: none);
* :meth:`~AgAccess.watch_removals` -- how the front ends a removed operator's sessions
  (the guard calls it when the operators file no longer has that operator).

:class:`SimpleAccess` is what runs today: loopback never needs a code; another
allowed address needs one only when ``require_token`` is set; codes map to
operators' names.
"""

from __future__ import annotations

from collections.abc import Callable, Iterable, Mapping
from typing import Protocol

from moas_gui.edge.admission import Admission
from moas_gui.net.access import allowed_networks, is_allowed, peer_address
from moas_gui.net.identity import Identity, is_local
from moas_gui.net.secrets import SecretGuard, SecretVerdict, budget_key


class AgAccess(Protocol):
    admission: Admission

    def identity(self, host: str, address: str, operator: str | None) -> Identity | None: ...

    def allowed(self, host: str) -> str | None: ...

    def needs_token(self, host: str) -> bool: ...

    async def check_code(self, code: str, host: str) -> SecretVerdict: ...

    def waiting(self, host: str) -> float: ...

    def watch_removals(self, end: Callable[[str], int] | None) -> None: ...


def is_loopback(host: str) -> bool:
    address = peer_address(host)
    return address is not None and address.is_loopback


class SimpleAccess:
    """Loopback and ``ClientAllow`` only; codes required beyond loopback only when
    ``require_token``; at most ``total`` connections, ``per_address`` from one address."""

    def __init__(self, client_allow: Callable[[], Iterable[str] | None] = lambda: None, *,
                 require_token: bool = False, codes: Mapping[str, str] | None = None,
                 guard: SecretGuard | None = None,
                 total: int = 64, per_address: int = 16) -> None:
        self.client_allow = client_allow
        self.require_token = require_token
        self.guard = guard if guard is not None else SecretGuard(codes=dict(codes or {}))
        """The station's one secret check (the server's, with its operators book; a
        test's own with ``codes``: code -> name)."""
        self._end: Callable[[str], int] | None = None
        self.identify: Callable[[str, str, str | None], Identity | None] | None = None
        """Who a connection is for the roles' rules (:mod:`moas_gui.net.identity`): the
        server's; None (tests): nobody in particular, which the rules let through."""

        self.admission = Admission(total, per_address, what="Antenna Genius connections")

    def identity(self, host: str, address: str, operator: str | None) -> Identity | None:
        return None if self.identify is None else self.identify(host, address, operator)

    def allowed(self, host: str) -> str | None:
        if not is_allowed(host, allowed_networks(self.client_allow())):
            return ("the address is not in the allowed networks (ClientAllow in the "
                    "configuration decides)")
        return None

    def needs_token(self, host: str) -> bool:
        """As for the client port: never from this computer (``127.0.0.1``, ``::1``);
        from the LAN (other loopback addresses count as the LAN) with ``require_token``."""
        return self.require_token and not is_local(host)

    async def check_code(self, code: str, host: str) -> SecretVerdict:
        return await self.guard.check_code(code, host)

    def waiting(self, host: str) -> float:
        return self.guard.addresses.wait(budget_key(host), self.guard.clock())

    def watch_removals(self, end: Callable[[str], int] | None) -> None:
        """The front's way to end an operator's sessions (None: the front closed):
        called when the operators file no longer has that operator."""
        if self._end is not None:
            self.guard.unlisten(self._end)
        self._end = end
        if end is not None:
            self.guard.listen(end)


__all__ = ["AgAccess", "SimpleAccess", "is_loopback"]
