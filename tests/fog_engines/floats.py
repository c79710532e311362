"""GPU arithmetic the transcriptions share: a value stored as a C++ float."""
import math
import struct


def f32(x):
    """x stored as a C++ float (round to nearest; overflow to +-inf)."""
    if math.isnan(x) or math.isinf(x):
        return x
    try:
        return struct.unpack("f", struct.pack("f", x))[0]
    except OverflowError:
        return math.copysign(math.inf, x)
