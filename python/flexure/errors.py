"""flexure's exceptions: the CLI's errors, as Python exceptions."""


class FlexureError(Exception):
    """Any error flexure reports: the base of `SceneError`, `OutputError` and `TooLargeError`.
    Also raised by itself for a request that cannot be met, e.g. `rigidity_matrix()` of a system
    that is no bar framework."""


class SceneError(FlexureError, ValueError):
    """Bad input: the key it concerns and why, as `flexure` reports it for a scene file. Also a
    `ValueError`.

    Attributes:

    - `key`: the scene key, e.g. `"system.edges[3]"` or `"motion.step_size"` (None when the
      problem is the whole document or a file's text: see `file`, `line`, `column`).
    - `reason`: the loader's message, e.g. `"edge vertex 12 is out of range: vertices are
      numbered 0..9"`.
    - `file`, `line`, `column`: where in a scene file (None for systems built in Python).

    `str(error)` is `FILE:LINE:COLUMN: reason` for a file, else `key: reason`.
    """

    def __init__(self, reason, key=None, file=None, line=None, column=None):
        self.reason = reason
        self.key = key
        self.file = file
        self.line = line
        self.column = column
        if file is not None and line is not None:
            text = f"{file}:{line}:{column}: {reason}"
        elif key is not None:
            text = f"{key}: {reason}"
        else:
            text = reason
        super().__init__(text)


def _SceneErrorFromLoader(file, line, column, message, item=None):
    """Made by the C++ module for a scene error; the System that loaded generated text turns
    the line into a key (see System._load), and `item`, the row of an array it gave as numbers,
    into the key's index."""
    err = SceneError(message, file=file, line=line, column=column)
    err._item = item
    return err


class OutputError(FlexureError, OSError):
    """An output could not be written (the command line's exit status 3; also when the name is a
    symbolic link, FIFO or device: only regular files are replaced), or was refused before any
    computation: a file name whose extension the call does not write (`render("a.jpg")`), or a
    scene named as a file of another format (`to_scene("a.off")`). Also an `OSError`; `filename`
    is the file."""

    def __str__(self):
        # The message as given: OSError's own would be "[Errno None] None: 'file'" once
        # `filename` is set.
        return str(self.args[0]) if len(self.args) == 1 else super().__str__()


class TooLargeError(FlexureError, MemoryError):
    """The input asks for more memory than the process can have (the estimate is in the
    message), refused before the work starts (the command line's exit status 1). Also a
    `MemoryError`."""


class Interrupted(KeyboardInterrupt):
    """Ctrl-C during a long call (a `KeyboardInterrupt`). `partial` holds what was computed
    before it: the `Path` so far, for `System.track`; None where nothing could be kept."""

    def __init__(self, message="interrupted", partial=None):
        super().__init__(message)
        self.partial = partial
