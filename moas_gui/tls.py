"""The server's TLS: its certificate, its fingerprint, and the contexts both sides use.

``moas-server --tls`` serves the client port and the web page over TLS with
``--tls-cert FILE --tls-key FILE``, or else with a self-signed certificate made
once (by the ``cryptography`` package) and kept in the configuration directory
(:func:`moas_gui.places.config_dir`) as ``tls-cert.pem`` and ``tls-key.pem``
(the key readable by the user alone).

A self-signed certificate proves nothing by itself: a client trusts it by its
**fingerprint**, the SHA-256 of the certificate (DER), written as 64 hex digits
in pairs (``AB:CD:...``).  ``moas-server --fingerprint`` prints it, the server
window shows it, and ``moas-client --pin`` compares it (:func:`client_context`
then checks nothing else, :func:`check_pin` checks that).
"""

from __future__ import annotations

import datetime
import hashlib
import hmac
import ipaddress
import logging
import os
import socket
import ssl
import sys
from collections.abc import Sequence
from dataclasses import dataclass
from pathlib import Path
from typing import Final

from moas_gui.errors import MoasError
from moas_gui.files import write_atomic
from moas_gui.places import config_dir

log = logging.getLogger(__name__)

CERT_NAME: Final = "tls-cert.pem"
KEY_NAME: Final = "tls-key.pem"
VALID_DAYS: Final = 3650


class TLSError(MoasError, ValueError):
    """A certificate or key that cannot be used; the message says which and why."""


@dataclass(frozen=True, slots=True)
class Certificate:
    cert: Path
    key: Path


def default_paths() -> Certificate:
    base = config_dir()
    return Certificate(base / CERT_NAME, base / KEY_NAME)


def certificate_names(host: str | None = None,
                      addresses: Sequence[str] = ()) -> tuple[list[str], list[str]]:
    """The names and IP addresses a self-signed certificate carries: ``localhost``,
    this computer's name, and ``addresses`` (the ones the server listens on)."""
    name = host or socket.gethostname() or "moas-server"
    names = ["localhost"] + ([name] if name != "localhost" else [])
    ips: list[str] = []
    for text in addresses:
        try:
            ips.append(str(ipaddress.ip_address(text.split("%")[0])))
        except ValueError:  # a name given as the bind address
            if text and text not in names:
                names.append(text)
    return names, list(dict.fromkeys(ips))


def carried_names(path: Path) -> tuple[list[str], list[str]] | None:
    """The names and IP addresses the certificate at ``path`` carries as subject
    alternative names; None when it cannot be read."""
    from cryptography import x509

    try:
        cert = x509.load_pem_x509_certificate(path.read_bytes())
        sans = cert.extensions.get_extension_for_class(x509.SubjectAlternativeName).value
    except (OSError, ValueError, x509.ExtensionNotFound):
        return None
    return ([str(n) for n in sans.get_values_for_type(x509.DNSName)],
            [str(a) for a in sans.get_values_for_type(x509.IPAddress)])


def make_self_signed(where: Certificate, host: str | None = None,
                     addresses: Sequence[str] = (), *, reuse_key: bool = False) -> None:
    """A new self-signed certificate (EC P-256) at ``where``, for this computer's name,
    ``localhost`` and ``addresses``; with ``reuse_key`` the key already at ``where`` signs
    it (a renewal: the key does not change), else a new key is made."""
    from cryptography import x509
    from cryptography.hazmat.primitives import hashes, serialization
    from cryptography.hazmat.primitives.asymmetric import ec
    from cryptography.x509.oid import NameOID

    names, ips = certificate_names(host, addresses)
    if reuse_key:
        loaded = serialization.load_pem_private_key(where.key.read_bytes(), password=None)
        if not isinstance(loaded, ec.EllipticCurvePrivateKey):
            raise TLSError(f"{where.key} is not the EC key this server makes")
        key = loaded
    else:
        key = ec.generate_private_key(ec.SECP256R1())
    subject = x509.Name([x509.NameAttribute(NameOID.COMMON_NAME,
                                            f"moas-server {names[-1]}"[:64])])
    now = datetime.datetime.now(datetime.UTC)
    general: list[x509.GeneralName] = [x509.DNSName(n) for n in names]
    general += [x509.IPAddress(ipaddress.ip_address(a)) for a in ips]
    cert = (x509.CertificateBuilder().subject_name(subject).issuer_name(subject)
            .public_key(key.public_key()).serial_number(x509.random_serial_number())
            .not_valid_before(now - datetime.timedelta(days=1))
            .not_valid_after(now + datetime.timedelta(days=VALID_DAYS))
            .add_extension(x509.SubjectAlternativeName(general), critical=False)
            .add_extension(x509.BasicConstraints(ca=False, path_length=None), critical=True)
            .sign(key, hashes.SHA256()))
    where.cert.parent.mkdir(parents=True, exist_ok=True)
    if not reuse_key:
        key_bytes = key.private_bytes(serialization.Encoding.PEM,
                                      serialization.PrivateFormat.PKCS8,
                                      serialization.NoEncryption())
        if not where.key.exists():
            os.close(os.open(where.key, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o600))
        write_atomic(where.key, key_bytes)
        if sys.platform != "win32":
            os.chmod(where.key, 0o600)
    write_atomic(where.cert, cert.public_bytes(serialization.Encoding.PEM))


def ensure_certificate(cert: str | None = None, key: str | None = None,
                       addresses: Sequence[str] | None = None) -> Certificate:
    """The certificate to serve: the files given, or the kept self-signed one (made now
    when there is none).  With ``addresses`` (those the server listens on), a kept
    certificate that does not carry exactly them and this computer's names is renewed
    with the same key.  :class:`TLSError` says what is wrong."""
    if (cert is None) != (key is None):
        raise TLSError("--tls-cert and --tls-key go together")
    if cert is not None and key is not None:
        given = Certificate(Path(cert), Path(key))
        for path in (given.cert, given.key):
            if not path.is_file():
                raise TLSError(f"{path} is not a file")
        return given
    kept = default_paths()
    if not (kept.cert.is_file() and kept.key.is_file()):
        make_self_signed(kept, addresses=addresses or ())
        log.info("Made a self-signed TLS certificate for %s",
                 _listed(certificate_names(None, addresses or ())))
        return kept
    if addresses is None:
        return kept
    wanted = certificate_names(None, addresses)
    carried = carried_names(kept.cert)
    if carried is None or (set(carried[0]), set(carried[1])) != (set(wanted[0]),
                                                                  set(wanted[1])):
        try:
            make_self_signed(kept, addresses=addresses, reuse_key=True)
        except ValueError as exc:  # a key file that cannot be read
            raise TLSError(f"cannot renew the certificate with the key {kept.key}: "
                           f"{exc}") from None
        log.info("Renewed the self-signed TLS certificate with the same key: it now names "
                 "%s (its fingerprint changed)", _listed(wanted))
    return kept


def _listed(names: tuple[list[str], list[str]]) -> str:
    return ", ".join([*names[0], *names[1]])


def server_context(where: Certificate) -> ssl.SSLContext:
    context = ssl.create_default_context(ssl.Purpose.CLIENT_AUTH)
    context.minimum_version = ssl.TLSVersion.TLSv1_2
    try:
        context.load_cert_chain(where.cert, where.key)
    except (OSError, ssl.SSLError) as exc:
        raise TLSError(f"cannot use the certificate {where.cert} with the key {where.key}: "
                       f"{exc}") from None
    return context


def format_fingerprint(der: bytes) -> str:
    digest = hashlib.sha256(der).hexdigest().upper()
    return ":".join(digest[i:i + 2] for i in range(0, len(digest), 2))


def fingerprint(where: Certificate) -> str:
    """The SHA-256 fingerprint of the certificate file's first certificate."""
    try:
        text = where.cert.read_text(encoding="ascii")
        der = ssl.PEM_cert_to_DER_cert(text)
    except (OSError, ValueError) as exc:
        raise TLSError(f"cannot read the certificate {where.cert}: {exc}") from None
    return format_fingerprint(der)


def normalize_pin(text: str) -> str:
    """A fingerprint as the user typed it (colons or not, any case) in the printed form;
    :class:`TLSError` when it is not 64 hex digits."""
    digits = "".join(ch for ch in text if ch not in ": ").upper()
    if len(digits) != 64 or any(ch not in "0123456789ABCDEF" for ch in digits):
        raise TLSError(f"{text!r} is not a SHA-256 fingerprint (64 hex digits, as "
                       "moas-server --fingerprint prints it)")
    return ":".join(digits[i:i + 2] for i in range(0, 64, 2))


def client_context() -> ssl.SSLContext:
    """For a client that pins the server's fingerprint: the certificate chain is not
    checked (a self-signed one has none); :func:`check_pin` is, right after connecting."""
    context = ssl.SSLContext(ssl.PROTOCOL_TLS_CLIENT)
    context.minimum_version = ssl.TLSVersion.TLSv1_2
    context.check_hostname = False
    context.verify_mode = ssl.CERT_NONE
    return context


def peer_fingerprint(ssl_object: ssl.SSLObject | ssl.SSLSocket) -> str:
    der = ssl_object.getpeercert(binary_form=True)
    if not der:
        raise TLSError("the server showed no certificate")
    return format_fingerprint(der)


def check_pin(seen: str, pinned: str) -> bool:
    return hmac.compare_digest(normalize_pin(seen), normalize_pin(pinned))


__all__ = [
    "CERT_NAME",
    "KEY_NAME",
    "Certificate",
    "TLSError",
    "carried_names",
    "certificate_names",
    "check_pin",
    "client_context",
    "default_paths",
    "ensure_certificate",
    "fingerprint",
    "format_fingerprint",
    "make_self_signed",
    "normalize_pin",
    "peer_fingerprint",
    "server_context",
]
