"""moas-gui: an open-source server, emulator, clients and rotator program for
the YCCC MOAS II antenna switch."""

__version__ = "0.1.0"

__all__ = ["__version__"]
