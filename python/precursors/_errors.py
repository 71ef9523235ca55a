"""The exceptions the package raises: the crate's errors, with its messages."""


class PrecursorsError(Exception):
    """Base class of every error of the crate.

    ``str(error)`` is the crate's message followed by its causes; ``error.kind`` names
    the crate's error variant (``"OutOfRange"``, ``"Io"``, ...).
    """

    kind: str = ""


class PrecursorsValueError(PrecursorsError, ValueError):
    """Bad input: a scene value out of range, a malformed scene file or checkpoint, a
    checkpoint of another scene, a corrupt table."""


class PrecursorsOSError(PrecursorsError, OSError):
    """A file or directory that cannot be read or written, a run directory that is not
    one or is locked by another run."""


class CudaUnavailableError(PrecursorsError, RuntimeError):
    """The CUDA backend (``backend="cuda"``) cannot run here: this build has no CUDA
    backend (the package is built without it), or no NVIDIA driver, GPU or CUDA library
    answers (docs/gpu.md)."""


class NotConvergedError(PrecursorsError):
    """A solve, a series or a fit that did not converge within its budget."""
