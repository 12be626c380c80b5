"""partita's exception classes. The C++ side raises them (python/src/module.cpp) with the message
the `partita` executable prints after "partita: error: "."""


class Error(Exception):
    """A user error of partita: bad input, a diverging run, a missing file.

    ``str(e)`` is the message the ``partita`` command prints (the rule, the value found, the fix).
    """

    def __init__(self, message, file="", line=0, column=0, key="", detail=""):
        super().__init__(message)
        self.message = message
        #: the input file the error is in ("" when it is about no file)
        self.file = file or None
        #: 1-based line and column in that file (None when unknown)
        self.line = line or None
        self.column = column or None
        #: the key path ("participants.ball.particles.diameter"; None when none)
        self.key = key or None
        #: the message without its "file:line:col: key '...': " prefix
        self.detail = detail or message


class CaseError(Error):
    """An error at one key of a case file: ``.file``, ``.line``, ``.column``, ``.key``."""


class InternalError(Error):
    """A condition partita does not check for yet (a bug): the message says how to report it."""


class UsageError(Error):
    """partita.ExternalParticipant called out of order or with a name the participant did not
    declare (a bug of the program)."""


class RunStopped(Error):
    """partita.ExternalParticipant: the run ended elsewhere (another participant failed, a signal,
    or the controller refused this process at start-up); the message says which."""
