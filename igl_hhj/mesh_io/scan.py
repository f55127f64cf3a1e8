"""A text body summarised line by line with numpy, in bounded chunks, and the messages
that name a bad line: the instrument of the file guards (:mod:`.guards`, :mod:`.ply`).

Memory O(number of lines) plus O(``_CHUNK``), time linear in the file size.
"""
from __future__ import annotations

import numpy as np

from ..errors import MeshFileError


def _too_short(path, what, need, have):
    raise MeshFileError(f"{path}: truncated or corrupt: the header declares {what}, which needs "
                        f"at least {need} bytes after the header, but the file has {have}")


_CHUNK = 1 << 22          # bytes of the file per vectorised pass (bounds temporary memory)


def _char_table(chars):
    t = np.zeros(256, dtype=bool)
    t[list(chars)] = True
    return t


_WS = _char_table(b" \t\r\n\v\f")
_NUMBER = _char_table(b"0123456789+-.eE")
_DIGIT = _char_table(b"0123456789")
_CORNER = _char_table(b"0123456789-/")


class _Lines:
    """A text body summarised per non-empty line, with numpy in bounded chunks.

    Memory is O(number of lines) plus O(``_CHUNK``); time is linear in the
    file size.  Everything after ``#`` on a line is a comment (``comments``).

    Attributes (arrays, one entry per non-empty line in file order)
    ----------
    offset : byte offset of the line in the file
    lineno : 1-based line number in the file
    ntok : number of whitespace-separated tokens
    c0, flen : first byte and length of the first token
    first : value of the first token if it is an integer of ≤ 18 digits, else -1
    n_num : how many tokens are numbers (float syntax)
    n_corner : how many tokens are OBJ face corners (``i``, ``i/j``, ``i//k``, ``-i``)
    zero_corner : one of those corners contains the index 0
    int_k : how many of tokens 2 .. 1 + first are non-negative integers (OFF face lines)
    maxlen : length of the longest token
    """

    FIELDS = ("offset", "lineno", "ntok", "c0", "flen", "first", "n_num", "n_corner",
              "zero_corner", "int_k", "maxlen")

    def __init__(self, path, start, comments=True, first_line=1, corners=False):
        parts = {k: [] for k in self.FIELDS}
        line0, pos0 = first_line, start
        with open(path, "rb") as fh:
            fh.seek(start)
            carry = b""
            while True:
                block = fh.read(_CHUNK)
                data = carry + block
                if block:
                    cut = data.rfind(b"\n") + 1
                    if cut == 0:
                        if len(data) <= _CHUNK:
                            carry = data
                            continue
                        summary, carry, length = self._long_line(fh, data, comments, corners)
                        if summary is not None:            # one line, streamed
                            for k, v in summary.items():
                                parts[k].append(v)
                            parts["lineno"][-1] += line0
                            parts["offset"][-1] += pos0
                        line0 += 1
                        pos0 += length
                        continue
                    data, carry = data[:cut], data[cut:]
                if data:
                    for k, v in self._scan(data, comments, corners).items():
                        parts[k].append(v)
                    parts["lineno"][-1] += line0
                    parts["offset"][-1] += pos0
                    line0 += data.count(b"\n")
                    pos0 += len(data)
                if not block:
                    break
        for k, v in parts.items():
            setattr(self, k, np.concatenate(v) if v else np.zeros(0, dtype=np.int64))

    _LONG_HEAD = 1 << 16
    """Bytes of an over-long line whose tokens are classified (the rest are only counted)."""

    def _long_line(self, fh, data, comments, corners):
        """Summarise a line longer than ``_CHUNK`` bytes (``data`` is its start, without a line
        break) by streaming it: memory O(``_CHUNK``) whatever its length (a valid file followed
        by a long tail of NUL bytes, an interrupted copy, must not cost 13x its size).

        Its first ``_LONG_HEAD`` bytes (cut at a space) are classified as usual; later tokens
        are counted but never as numbers or indices, so a check that needs them refuses the
        line (by name) rather than trusting it, and a line no check reads costs nothing.
        Returns ``(summary or None, the bytes after the line break, bytes of the line with its
        break)``."""
        head = data[:self._LONG_HEAD]
        sp = max(head.rfind(c) for c in (b" ", b"\t", b"\r", b"\v", b"\f"))
        head = head[:sp] if sp > 0 else head
        summary = self._scan(head + b"\n", comments, corners) if head.strip() else None
        if summary is not None and not len(summary["ntok"]):
            summary = None
        counted = len(head)
        ntok = int(summary["ntok"][0]) if summary is not None else 0
        prev_space = True
        in_comment = comments and b"#" in head
        length = counted
        rest = data[counted:]
        while True:
            nl = rest.find(b"\n")
            piece = rest if nl < 0 else rest[:nl]
            if not in_comment and piece:
                if comments and b"#" in piece:
                    piece = piece[:piece.find(b"#")]
                    in_comment = True
                buf = np.frombuffer(piece, dtype=np.uint8)
                if buf.size:
                    space = _WS[buf]
                    starts = int(np.count_nonzero(~space[1:] & space[:-1])) + int(prev_space and not space[0])
                    ntok += starts
                    prev_space = bool(space[-1])
            length += len(rest) if nl < 0 else nl + 1
            if nl >= 0:
                after = rest[nl + 1:]
                break
            rest = fh.read(_CHUNK)
            if not rest:
                after = b""
                break
        if summary is None:
            if ntok == 0:
                return None, after, length
            summary = self._scan(b"\x00\n", comments, corners)     # a line of one non-number token
        summary["ntok"] = np.array([ntok], dtype=np.int64)
        summary["maxlen"] = np.array([length], dtype=np.int64)
        return summary, after, length

    def __len__(self):
        return len(self.ntok)

    @staticmethod
    def _scan(data, comments, corners):
        buf = np.frombuffer(data, dtype=np.uint8)
        n = buf.size
        space = _WS[buf]
        nl = np.flatnonzero(buf == 10)
        if comments and b"#" in data:
            hashes = np.flatnonzero(buf == 35)
            ends = np.append(nl, n)[np.searchsorted(nl, hashes)]     # end of each comment
            delta = np.zeros(n + 1, dtype=np.int32)
            np.add.at(delta, hashes, 1)
            np.add.at(delta, ends, -1)
            space |= np.cumsum(delta[:n]) > 0
        inside = ~space
        before = np.empty(n, dtype=bool)                            # previous char is space
        before[0] = True
        before[1:] = space[:-1]
        s = np.flatnonzero(inside & before)                         # token starts
        before[:-1] = space[1:]                                     # (reused: next char is space)
        before[-1] = True
        e = np.flatnonzero(inside & before) + 1                     # token ends (exclusive)
        del before
        line = np.searchsorted(nl, s)                               # line of each token (block)
        head = np.flatnonzero(np.concatenate([[True], line[1:] != line[:-1]])) if s.size \
            else np.zeros(0, dtype=np.int64)
        ntok = np.diff(np.append(head, s.size))
        owner = np.repeat(np.arange(head.size), ntok)               # line (table row) of each token
        pos = np.arange(s.size) - head[owner] if s.size else np.zeros(0, dtype=np.int64)
        starts = np.concatenate([[0], nl + 1])[line[head]] if head.size else head

        pre = np.empty(n + 1, dtype=np.int32)                       # n ≤ 2 × _CHUNK < 2³¹
        pre[0] = 0

        def count(mask):                                            # per token: chars in mask
            np.cumsum(mask & inside, dtype=np.int32, out=pre[1:])
            return pre[e] - pre[s]

        def every(table):                                           # every character of the token
            return count(~table[buf]) == 0

        has_digit = count(_DIGIT[buf]) > 0
        digits = every(_DIGIT)
        number = every(_NUMBER) & has_digit
        corner = np.zeros(s.size, dtype=bool)
        zero = np.zeros(s.size, dtype=bool)
        if corners:                                                 # OBJ face corners
            corner = every(_CORNER) & has_digit
            zc = np.flatnonzero(buf == 48)                          # a component "0" of a corner
            before = np.where(zc > 0, buf[np.maximum(zc - 1, 0)], 32)
            after = np.where(zc < n - 1, buf[np.minimum(zc + 1, n - 1)], 32)
            zc = zc[((before == 47) | _WS[before]) & ((after == 47) | _WS[after])]
            if zc.size and s.size:
                t = np.searchsorted(s, zc, side="right") - 1
                zero[t[(t >= 0) & (zc < e[np.maximum(t, 0)])]] = True
        fs, flen = s[head], (e - s)[head]
        first = np.where(digits[head] & (flen <= 18), 0, -1).astype(np.int64)
        for j in range(18):
            m = (first >= 0) & (j < flen)
            first[m] = first[m] * 10 + (buf[fs[m] + j].astype(np.int64) - 48)
        kk = first[owner] if s.size else pos

        def per_line(x):
            return np.bincount(owner, weights=x, minlength=head.size).astype(np.int64)

        return {"offset": starts.astype(np.int64), "lineno": line[head].astype(np.int64),
                "ntok": ntok.astype(np.int64), "c0": buf[fs].astype(np.int64),
                "flen": flen.astype(np.int64), "first": first,
                "n_num": per_line(number), "n_corner": per_line(corner),
                "zero_corner": per_line(corner & zero) > 0,
                "int_k": per_line((pos > 0) & (pos <= kk) & digits),
                "maxlen": (np.maximum.reduceat(e - s, head) if head.size
                           else np.zeros(0, dtype=np.int64)).astype(np.int64)}

    def text(self, path, i, limit=60):
        """The i-th non-empty line (at most ``limit`` characters), for messages."""
        with open(path, "rb") as fh:
            fh.seek(int(self.offset[i]))
            raw = fh.readline(limit + 1).rstrip(b"\r\n")
        txt = raw[:limit].decode("ascii", "replace")
        return txt + ("..." if len(raw) > limit else "")


def _long_lines(path, limit):
    """The lines of at least ``limit`` bytes (line break excluded; every byte counts, blanks
    and NUL too), streamed in ``_CHUNK`` blocks: ``(offset, length, lineno)`` int64 arrays,
    one entry per such line in file order.  Memory O(``_CHUNK``) plus O(such lines)."""
    offsets, lengths, linenos = [], [], []
    start, lineno, pos = 0, 1, 0                   # the current line's offset and number
    with open(path, "rb") as fh:
        while True:
            block = fh.read(_CHUNK)
            if not block:
                break
            nl = np.flatnonzero(np.frombuffer(block, dtype=np.uint8) == 10) + pos
            if nl.size:
                begins = np.concatenate([[start], nl[:-1] + 1])
                length = nl - begins
                long = np.flatnonzero(length >= limit)
                offsets.append(begins[long])
                lengths.append(length[long])
                linenos.append(long + lineno)
                start, lineno = int(nl[-1]) + 1, lineno + nl.size
            pos += len(block)
    if pos - start >= limit:                       # the last line, without a line break
        offsets.append(np.array([start]))
        lengths.append(np.array([pos - start]))
        linenos.append(np.array([lineno]))
    cat = [np.concatenate(x).astype(np.int64) if x else np.zeros(0, dtype=np.int64)
           for x in (offsets, lengths, linenos)]
    return tuple(cat)


def _first_bad(path, lines, bad, what):
    """Raise MeshFileError naming the first line where ``bad`` holds."""
    i = int(np.flatnonzero(bad)[0])
    n = int(bad.sum())
    more = f" ({n} such lines)" if n > 1 else ""
    raise MeshFileError(f"{path}: line {int(lines.lineno[i])}: {what}{more}: "
                        f"{lines.text(path, i)!r}")


def _line_tokens(fh, L, i):
    """Tokens of the i-th non-empty line (comments removed), read from the open file."""
    fh.seek(int(L.offset[i]))
    return fh.readline().split(b"#")[0].split()


def _check_rows(path, L, rows, bad, what):
    if bad.any():
        mask = np.zeros(len(L), dtype=bool)
        mask[rows] = bad
        _first_bad(path, L, mask, what)
