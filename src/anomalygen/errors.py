"""Exception types that the CLI turns into one-line messages instead of tracebacks."""


class AnomalygenError(Exception):
    """Base class for expected failures."""


class UserError(AnomalygenError):
    """A mistake in the user's input: bad path, bad config value, unreadable file."""


class ItemFailed(AnomalygenError):
    """One item of a stage failed; the batch carries on and records the reason."""

