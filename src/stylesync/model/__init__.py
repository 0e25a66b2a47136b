"""The character: its description (``character.py``), the values that describe its state (``state.py``), the
engine's rigid-body data (``body_description.py``) and the Pinocchio model built from it (``character_model.py``)."""
