"""veil's one exception type, and its subclass for a cancelled render."""

from ._lib import RESULT_CODES

_NAMES = {code: name for name, code in RESULT_CODES.items()}


class VeilError(Exception):
    """A veil call failed.

    Attributes:
        code: the veil_result (int), e.g. 2
        name: its name, e.g. "VEIL_ERR_PARSE"
        message: veil's sentence: the file, the JSON path of the field
            ("demo.json: camera.fov_y_deg: expected a number ..."), or the
            call and what went wrong
    """

    def __init__(self, code, message, name=None):
        self.code = int(code)
        self.name = name or _NAMES.get(self.code, "VEIL_ERR_%d" % self.code)
        self.message = message
        super().__init__(code, message)

    def __str__(self):
        return "%s: %s" % (self.name, self.message)


class Cancelled(VeilError):
    """The render was cancelled (VEIL_ERR_CANCELLED): the progress callback
    returned False, or raised (that exception is raised instead, with this
    one as its context), or Ctrl-C was pressed. No image was made and no
    file written."""


def raise_for(lib, code, err):
    """Raises the VeilError of a failed call (code != 0) with veil's message."""
    if code == 0:
        return
    name = lib.veil_result_name(code)
    name = name.decode() if name else None
    message = err.msg.decode("utf-8", "replace") if err is not None else ""
    if not message:  # the library always writes one; the generic text if not
        generic = lib.veil_result_message(code)
        message = generic.decode() if generic else "veil call failed"
    cls = Cancelled if code == RESULT_CODES["VEIL_ERR_CANCELLED"] else VeilError
    raise cls(code, message, name)
