"""Serving HTTPS directly: a certificate and its key, checked before a server starts.

uvicorn loads them only once its server runs (in each worker), where a bad file becomes a
traceback in the log; here each file is named in one line instead.
"""

from __future__ import annotations

import ssl
from pathlib import Path

from engine.errors import ConfigError


def tls_options(certfile: str | None, keyfile: str | None) -> dict[str, str]:
    """uvicorn's options for serving HTTPS with the PEM certificate (chain) in ``certfile``
    and its private key in ``keyfile`` (unencrypted); none for plain HTTP (neither given).
    A ConfigError naming the option and file when one is missing, unreadable, not PEM, or
    the key is not the certificate's."""
    if certfile is None and keyfile is None:
        return {}
    if certfile is None or keyfile is None:
        given, missing = (
            ("--certfile", "--keyfile") if keyfile is None else ("--keyfile", "--certfile")
        )
        raise ConfigError(f"{given} needs {missing} too (a certificate and its private key)")
    _pem(certfile, "--certfile", "CERTIFICATE", "a PEM certificate")
    _pem(keyfile, "--keyfile", "PRIVATE KEY", "a PEM private key")
    context = ssl.SSLContext(ssl.PROTOCOL_TLS_SERVER)
    try:
        context.load_cert_chain(certfile, keyfile, password=_no_password)
    except ssl.SSLError as error:
        if "KEY_VALUES_MISMATCH" in str(error):
            raise ConfigError(
                f"--keyfile {keyfile}: not the private key of --certfile {certfile}"
            ) from None
        raise ConfigError(
            f"--certfile {certfile} / --keyfile {keyfile}: cannot be used ({error.reason or error})"
        ) from None
    except _EncryptedKeyError:
        raise ConfigError(
            f"--keyfile {keyfile}: the key is encrypted; give an unencrypted key "
            f"(openssl pkey -in {keyfile} -out plain.key)"
        ) from None
    return {"ssl_certfile": certfile, "ssl_keyfile": keyfile}


class _EncryptedKeyError(Exception):
    """The key asked for a password (a service cannot type one)."""


def _no_password() -> str:
    raise _EncryptedKeyError


def _pem(path: str, option: str, label: str, what: str) -> None:
    """The file at ``path`` exists, can be read, and holds a PEM block of ``label``."""
    try:
        text = Path(path).read_text(encoding="ascii", errors="replace")
    except FileNotFoundError:
        raise ConfigError(f"{option} {path}: no such file") from None
    except OSError as error:
        raise ConfigError(f"{option} {path}: cannot read it ({error.strerror or error})") from None
    if "-----BEGIN " not in text or f"{label}-----" not in text:
        raise ConfigError(f"{option} {path}: not {what} (no '-----BEGIN ...{label}-----' in it)")
