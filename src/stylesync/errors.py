"""Exceptions. Every error a user can cause derives from :class:`StylesyncError` and carries a one-line message
that says what was wrong and what would be valid."""


class StylesyncError(Exception):
    """Root of all stylesync errors."""


class ConfigError(StylesyncError):
    """An invalid configuration value (negative gain, cut-off <= 0, unknown clip, ...)."""


class SourceError(StylesyncError):
    """An operator source could not be opened or read (missing file, malformed data, silent stream)."""


class SimulationError(StylesyncError):
    """The physics engine could not be set up or stepped."""
