"""moas_gui.builder: the station builder's model, with no Qt (a web builder can follow on it).

:class:`~.document.Document` edits a ``.moas`` file value by value, keeping everything
else of the user's text; :mod:`.checking` gives the ``--check`` findings with the field
each is about; :mod:`.whatif` asks a fresh engine built from the draft; :mod:`.guide`
makes a new station; :mod:`.claims` keeps two builder windows off one file.
See ``docs/builder.md``.
"""

from moas_gui.config.model import RadioRef

from .document import NEW_STATION, Document, EditError, EditStep, backup_of

__all__ = ["NEW_STATION", "Document", "EditError", "EditStep", "RadioRef", "backup_of"]
