"""Reading ``.npy`` data (alone or as a member of an ``.npz``): the header checked (shape, dtype,
size within the limits) before anything is allocated, never a pickle."""

from __future__ import annotations


import numpy as np

from .._checks import check_bytes, short_token


_ZIP_MAGIC = b"PK\x03\x04"
_EMPTY_ZIP_MAGIC = b"PK\x05\x06"
_NPY_MAGIC = b"\x93NUMPY"


def _read_npy_header(stream, what: str, check=None) -> tuple[tuple, np.dtype]:
    """Read an ``.npy`` header from ``stream``; refuse object dtypes and sizes over the limits."""
    magic = stream.read(len(_NPY_MAGIC))
    if magic != _NPY_MAGIC:
        raise ValueError(f"{what} is not an .npy array")
    version = tuple(stream.read(2))
    try:  # the header is a Python literal: a corrupt one can fail in many ways
        if version == (1, 0):
            shape, _, dtype = np.lib.format.read_array_header_1_0(stream)
        elif version in ((2, 0), (3, 0)):
            shape, _, dtype = np.lib.format.read_array_header_2_0(stream)
        else:
            raise ValueError(f"{what} has an unknown .npy format version {version}")
    except ValueError:
        raise
    except Exception as exc:  # noqa: BLE001 - numpy parses the header with ast/tokenize, which fail in many ways
        raise ValueError(f"{what} has a corrupt .npy header ({type(exc).__name__})") from None
    if not (isinstance(shape, tuple) and all(isinstance(n, int) and n >= 0 for n in shape)):
        raise ValueError(f"{what} has a corrupt .npy header (shape {short_token(shape, 30)})")
    if dtype.hasobject or dtype.kind not in "fiub":
        raise ValueError(f"{what} holds {dtype} data, not real numbers")
    if len(shape) > 8:
        raise ValueError(f"{what} has {len(shape)} dimensions")
    if check is not None:  # the caller's own expectations first: they give the clearer message
        check(shape, dtype)
    n_elements = int(np.prod(shape, dtype=object))
    check_bytes(n_elements, what, dtype.itemsize)
    return shape, dtype


def _read_npy(open_stream, what: str, check=None) -> np.ndarray:
    """Read an array from the stream factory ``open_stream`` after checking its header
    (``check(shape, dtype)`` may refuse more)."""
    with open_stream() as stream:
        _read_npy_header(stream, what, check)
    with open_stream() as stream:
        try:
            return np.lib.format.read_array(stream, allow_pickle=False)
        except (ValueError, EOFError, OSError):
            raise
        except Exception as exc:  # noqa: BLE001 - as above: a corrupt header or body
            raise ValueError(f"{what} is not a readable .npy array ({type(exc).__name__})") from None
