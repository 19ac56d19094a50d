# SPDX-License-Identifier: Apache-2.0
"""Exceptions: one class per vp_result, all under vdbpack.Error."""


class Error(Exception):
    """A call into libvdbpack failed. ``code`` is the vp_result's name
    ("VP_ERR_IO", ...), ``message`` the library's one-line message (also
    ``str(error)``)."""

    code = "VP_ERR_UNKNOWN"

    def __init__(self, message, code=None):
        super().__init__(message)
        self.message = message
        if code is not None:
            self.code = code

    def __str__(self):
        return self.message


class InvalidArgumentError(Error, ValueError):
    """VP_ERR_INVALID_ARGUMENT: a parameter is out of range or malformed."""
    code = "VP_ERR_INVALID_ARGUMENT"


class FileError(Error, OSError):
    """VP_ERR_IO: a file could not be read or written."""
    code = "VP_ERR_IO"


class FormatError(Error):
    """VP_ERR_FORMAT: a file is not of the expected kind or is corrupt."""
    code = "VP_ERR_FORMAT"


class OpenMeshError(Error):
    """VP_ERR_OPEN_MESH: the mesh has boundary or non-manifold edges (with
    inside="closed")."""
    code = "VP_ERR_OPEN_MESH"


class NotLevelSetError(Error):
    """VP_ERR_NOT_LEVEL_SET: a .vdb holds no usable float level set."""
    code = "VP_ERR_NOT_LEVEL_SET"


class BadContainerError(Error):
    """VP_ERR_BAD_CONTAINER: the container is empty or its inside leaks."""
    code = "VP_ERR_BAD_CONTAINER"


class NoFitError(Error):
    """VP_ERR_NO_FIT: no particle fits in the container."""
    code = "VP_ERR_NO_FIT"


class OutOfMemoryError(Error, MemoryError):
    """VP_ERR_OUT_OF_MEMORY: an allocation failed or the job's estimate is
    above the memory limit (max_memory)."""
    code = "VP_ERR_OUT_OF_MEMORY"


class CancelledError(Error):
    """VP_ERR_CANCELLED: the progress callback asked to stop."""
    code = "VP_ERR_CANCELLED"


class InternalError(Error):
    """VP_ERR_INTERNAL: a bug in vdbpack; please report it."""
    code = "VP_ERR_INTERNAL"


# by vp_result value (the order of the enum in vdbpack.h)
BY_RESULT = {
    1: InvalidArgumentError, 2: FileError, 3: FormatError, 4: OpenMeshError,
    5: NotLevelSetError, 6: BadContainerError, 7: NoFitError, 8: OutOfMemoryError,
    9: CancelledError, 10: InternalError,
}
