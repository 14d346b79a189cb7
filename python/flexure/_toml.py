"""Scene documents (nested dicts, as tomllib reads them) to TOML text, and back to dicts.

The text is what the scene loader reads, so a system built from arrays goes through exactly
the same validation as a scene file. It is written one array element per line for arrays of
arrays, and the writer records which key each line holds, so that an error the loader reports
at a line and column can be given back to Python as the key (e.g. ``system.edges[3]``).
"""

import decimal
import itertools
import math
import numbers
import re

_BARE = re.compile(r"^[A-Za-z0-9_-]+$")

# The top-level tables in the order a scene file has them.
_TABLE_ORDER = ["system", "motion", "analysis", "render", "projection"]


def _key(k):
    if not isinstance(k, str):
        raise TypeError(f"a key must be a string, not {type(k).__name__}")
    return k if _BARE.match(k) else _string(k)


def _string(s):
    out = ['"']
    for ch in s:
        o = ord(ch)
        if ch == '"':
            out.append('\\"')
        elif ch == "\\":
            out.append("\\\\")
        elif ch == "\n":
            out.append("\\n")
        elif ch == "\t":
            out.append("\\t")
        elif o < 0x20 or o == 0x7F:
            out.append(f"\\u{o:04X}")
        elif 0xD800 <= o <= 0xDFFF:
            raise ValueError("a string holds a lone surrogate, which TOML cannot write")
        else:
            out.append(ch)
    out.append('"')
    return "".join(out)


def _plain(v):
    """numpy scalars and arrays as Python values (without importing numpy here)."""
    tolist = getattr(v, "tolist", None)
    if tolist is not None and not isinstance(v, (str, bytes)):
        return tolist()
    return v


def _float(f):
    if math.isnan(f):
        return "nan"
    if math.isinf(f):
        return "inf" if f > 0 else "-inf"
    r = repr(f)
    return r if ("." in r or "e" in r or "n" in r) else r + ".0"


# The exact mode's limit on a scene number (engine/exact/rational.h kMaxRationalBits): bits of the
# numerator and of the denominator together.
MAX_RATIONAL_BITS = 400000


def _digits(n):
    """The decimal digits of an int of any size (str() refuses more than 4300 digits; Decimal's
    conversion has no such limit and is exact)."""
    return str(n) if n.bit_length() < 10000 else str(decimal.Decimal(n))


def _ratio(p, q, where):
    """The string "p/q" of a rational, refused (ValueError naming `where`) beyond the size the
    exact mode holds, which the loader would refuse too."""
    bits = abs(p).bit_length() + q.bit_length()
    if bits > MAX_RATIONAL_BITS:
        raise ValueError(f"{where}: a rational number of {bits} bits (numerator and denominator together) is beyond "
                         f"the limit of {MAX_RATIONAL_BITS} bits for a scene number")
    return _string(f"{_digits(p)}/{_digits(q)}")


def value(v, where="value"):
    """The TOML text of one value (inline)."""
    v = _plain(v)
    if isinstance(v, bool):
        return "true" if v else "false"
    if isinstance(v, numbers.Integral):
        return str(int(v))
    if isinstance(v, numbers.Rational):
        # fractions.Fraction: "p/q", which the exact mode reads exactly (and the loader as p/q)
        return _ratio(int(v.numerator), int(v.denominator), where)
    if isinstance(v, float):
        return _float(v)
    if isinstance(v, decimal.Decimal):
        # Its own numeral, which the exact mode reads exactly (docs/exact.md), never a double:
        # Decimal("0.1000000000000000000001") is not 0.1.
        if not v.is_finite():
            return _float(float("nan") if v.is_nan() else float(v))
        t = str(v)  # "-1.5", "1E+2", "1.2E-7", "123": TOML integers and floats
        if "E" not in t and "." not in t and len(t.lstrip("-")) > 18:
            t += ".0"  # beyond TOML's 64-bit integers: a float numeral, read exactly all the same
        return t
    if isinstance(v, numbers.Real):
        # numpy.longdouble and any other real: exactly. A value that is a double is written as
        # one; else "p/q" of its exact ratio (its double would be a different number).
        f = float(v)
        if math.isnan(f) or math.isinf(f):
            return _float(f)
        ratio = getattr(v, "as_integer_ratio", None)
        if ratio is not None:
            p, q = ratio()
            if f.as_integer_ratio() == (p, q):
                return _float(f)
            return _ratio(int(p), int(q), where)
        if f == v:
            return _float(f)
        raise TypeError(f"{where}: {v!r} ({type(v).__name__}) cannot be written exactly: give a float, a "
                        "fractions.Fraction or a decimal.Decimal")
    if isinstance(v, str):
        return _string(v)
    if isinstance(v, dict):
        return "{" + ", ".join(f"{_key(k)} = {value(x, where)}" for k, x in v.items()) + "}"
    if isinstance(v, (list, tuple)):
        return "[" + ", ".join(value(x, where) for x in v) + "]"
    raise TypeError(f"{where}: cannot write {type(v).__name__} to a scene")


def _is_table_array(v):
    return isinstance(v, (list, tuple)) and len(v) > 0 and all(isinstance(x, dict) for x in v)


def dumps(doc):
    """(text, lines): the TOML text of `doc` and, per line (1-based, index 0 unused), the key it
    holds, e.g. "system.vertices[4]"."""
    lines = [None]
    out = []

    def emit(text, key):
        out.append(text)
        lines.append(key)

    def body(table, prefix):
        for k, v in table.items():
            if not prefix and (isinstance(v, dict) or _is_table_array(v)):
                continue  # the tables and [[arrays of tables]], after the keys; deeper ones inline
            key = f"{prefix}{k}"
            v = _plain(v)
            if isinstance(v, (list, tuple)) and len(v) > 0 and all(
                isinstance(_plain(x), (list, tuple)) for x in v
            ):
                emit(f"{_key(k)} = [", key)
                rows = [_plain(x) for x in v]
                # Rows of plain floats and ints (what numpy's tolist gives) are written by repr, in
                # C: the same text as value() (a float's repr always has '.', 'e', 'inf' or 'nan',
                # TOML's forms), about 20 times faster for 10^4-vertex systems.
                numbers_only = all(type(x) is list for x in rows) and set(
                    map(type, itertools.chain.from_iterable(rows))) <= {float, int}
                if numbers_only:
                    out.extend(map("  {},".format, rows))  # str(list) is its repr
                    lines.extend(map(f"{key}[{{}}]".format, range(len(rows))))
                else:
                    for i, x in enumerate(rows):
                        emit(f"  {value(x, f'{key}[{i}]')},", f"{key}[{i}]")
                emit("]", key)
            else:
                emit(f"{_key(k)} = {value(v, key)}", key)

    body(doc, "")
    names = [k for k in _TABLE_ORDER if k in doc] + [
        k for k, v in doc.items() if k not in _TABLE_ORDER and (isinstance(v, dict) or _is_table_array(v))
    ]
    for name in names:
        v = doc[name]
        if isinstance(v, dict):
            emit("", None)
            emit(f"[{_key(name)}]", name)
            body(v, f"{name}.")
        elif _is_table_array(v):
            for i, t in enumerate(v):
                emit("", None)
                emit(f"[[{_key(name)}]]", f"{name}[{i}]")
                body(t, f"{name}[{i}].")
        else:
            raise TypeError(f"{name} must be a table")
    return "\n".join(out) + "\n", lines
