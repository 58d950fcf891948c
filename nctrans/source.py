"""Reading a part program: bytes -> normalised text, a line index for spans, and NC001/NC004.

Programs come off USB sticks, DNC links and Windows editors: UTF-8 with or without BOM, CP1252 or
CP1250 comments, CR/LF/CRLF line ends, tape-control characters, NUL padding, sometimes a UTF-16 save
or a binary file by mistake. This module turns all of that into one form the front ends can rely on:
LF line ends, no control characters but TAB (each replaced by one space so columns stay put), and a
final newline. Decoding never fails on an 8-bit file; what is not text at all becomes an NC001
diagnostic with empty text. Files are only read, never written.
"""
from __future__ import annotations

import bisect
import os
import re
import stat
import sys
from dataclasses import dataclass, field
from pathlib import Path
from typing import Optional

from nctrans import limits
from nctrans.diagnostics import Diagnostic

STDIN = "-"
STDIN_LABEL = "<stdin>"

_UTF8_BOM = b"\xef\xbb\xbf"
_UTF16_BOMS = (b"\xff\xfe", b"\xfe\xff")
_UTF32_BOMS = (b"\xff\xfe\x00\x00", b"\x00\x00\xfe\xff")
_SNIFF_BYTES = 8192
# control bytes that do appear in real programs: TAB, LF, CR, FF, VT, ^Z (DOS EOF), DC1-DC4 (tape
# reader on/off), ESC is rare but harmless. The rest in quantity means binary data.
_TEXTISH_CONTROLS = frozenset(b"\t\n\r\x0b\x0c\x1a\x11\x12\x13\x14")
_BINARY_CONTROL_RATIO = 0.05
# characters replaced by a space in the decoded text: C0/C1 controls except TAB/LF, DEL, stray BOMs
_STRAY = re.compile("[\x00-\x08\x0b-\x1f\x7f-\x9f\ufeff]")
_ASCII_STRAY = bytes(range(0x00, 0x09)) + bytes(range(0x0B, 0x20)) + b"\x7f"   # _STRAY's ASCII part


class SourceError(Exception):
    """The file cannot be read at all (missing, a directory, no permission): a usage error, exit 2."""


@dataclass
class SourceText:
    """A decoded program. `text` is "" when the bytes are not program text (see diagnostics)."""
    text: str
    encoding: str
    diagnostics: list[Diagnostic] = field(default_factory=list)
    file: str = STDIN_LABEL
    had_final_newline: bool = True
    _starts: Optional[list[int]] = field(default=None, repr=False, compare=False)

    @property
    def line_starts(self) -> list[int]:
        """Offset of each line's first character; computed when first asked (diagnostics,
        editors), not for every run of a 20k-line file."""
        if self._starts is None:
            self._starts = _line_starts(self.text)
        return self._starts

    @property
    def ok(self) -> bool:
        """True when the text is worth parsing (no error from reading)."""
        return not any(d.severity == "error" for d in self.diagnostics)

    @property
    def line_count(self) -> int:
        return len(self.line_starts) - (1 if self.text.endswith("\n") else 0)

    def location(self, offset: int) -> tuple[int, int]:
        """1-based (line, column) of a character offset into `text`."""
        i = bisect.bisect_right(self.line_starts, offset) - 1
        return i + 1, offset - self.line_starts[i] + 1

    def offset(self, line: int, column: int = 1) -> int:
        """Character offset of a 1-based (line, column)."""
        return self.line_starts[line - 1] + column - 1

    def line(self, n: int) -> str:
        """Text of 1-based line n without its newline ("" past the end)."""
        if n < 1 or n > len(self.line_starts):
            return ""
        start = self.line_starts[n - 1]
        end = self.text.find("\n", start)
        return self.text[start:] if end < 0 else self.text[start:end]


def _line_starts(text: str) -> list[int]:
    starts = [0]
    find = text.find
    i = find("\n")
    while i >= 0:
        starts.append(i + 1)
        i = find("\n", i + 1)
    return starts


def _looks_utf16(head: bytes) -> str | None:
    """'utf-16-le'/'utf-16-be' when every other byte is NUL (UTF-16 of mostly-ASCII text)."""
    n = len(head) // 2 * 2
    if n < 4:
        return None
    even_nul = head[0:n:2].count(0)
    odd_nul = head[1:n:2].count(0)
    pairs = n // 2
    if odd_nul >= 0.7 * pairs and even_nul <= 0.1 * pairs:
        return "utf-16-le"
    if even_nul >= 0.7 * pairs and odd_nul <= 0.1 * pairs:
        return "utf-16-be"
    return None


def _unreadable(file: str, message: str, encoding: str) -> SourceText:
    return SourceText("", encoding, [Diagnostic("NC001", "error", message, file, 1, 1)], file)


# letters that only CP1250 (Central European) gives a letter for, where CP1252 gives a symbol or
# nothing: scoring both decodings by letter count picks CP1250 for Polish/Czech/Hungarian comments.
def _letter_score(data: bytes, encoding: str) -> int:
    score = 0
    for b in set(data):
        if b < 0x80:
            continue
        try:
            ch = bytes([b]).decode(encoding)
        except UnicodeDecodeError:
            score -= 4 * data.count(b)
            continue
        if ch.isalpha():
            score += data.count(b)
    return score


def _decode_8bit(data: bytes) -> tuple[str, str]:
    """Strict UTF-8, else CP1252, or CP1250 when its reading yields more letters. Never fails."""
    try:
        return data.decode("utf-8"), "utf-8"
    except UnicodeDecodeError:
        pass
    high = bytes(b for b in data if b >= 0x80)
    enc = "cp1250" if _letter_score(high, "cp1250") > _letter_score(high, "cp1252") else "cp1252"
    return data.decode(enc, errors="replace"), enc


def decode(data: bytes, file: str = STDIN_LABEL) -> SourceText:
    """Turn raw bytes into a SourceText (see module docstring). Never raises on bad input."""
    if data.startswith(_UTF32_BOMS):
        return _unreadable(file, "UTF-32 text: save as UTF-8/ASCII", "utf-32")
    if data.startswith(_UTF16_BOMS):
        return _unreadable(file, "UTF-16 text: save as UTF-8/ASCII", "utf-16")
    bom = data.startswith(_UTF8_BOM)
    if bom:
        data = data[len(_UTF8_BOM):]
    # NUL padding after the program (DNC transfers, fixed-size sectors) is not content
    body = data.rstrip(b"\x00\x1a")
    head = body[:_SNIFF_BYTES]
    utf16 = _looks_utf16(head)
    if utf16:
        return _unreadable(file, "UTF-16 text: save as UTF-8/ASCII", utf16)
    if b"\x00" in body:
        nul = body.index(b"\x00")
        return _unreadable(file, f"binary data (NUL byte at offset {nul}): not an NC program", "binary")
    if head:
        controls = sum(1 for b in head if (b < 0x20 or b == 0x7F) and b not in _TEXTISH_CONTROLS)
        if controls > max(4, _BINARY_CONTROL_RATIO * len(head)):
            return _unreadable(file, f"binary data ({controls} control bytes in the first {len(head)}):"
                                     " not an NC program", "binary")
    if bom:
        text, encoding = body.decode("utf-8", errors="replace"), "utf-8-sig"
    else:
        text, encoding = _decode_8bit(body)
    del data, body, head            # the bytes go before normalising: peak = bytes + text, not more
    return from_text(text, file, encoding)


def _ascii_stray(text: str, chunk: int = 1 << 16) -> bool:
    """Whether ASCII `text` holds a stray control character: bytes.translate (10x faster than
    searching with _STRAY) a piece at a time, so that checking a long program copies none of it
    whole (streamed parses keep memory flat)."""
    for i in range(0, len(text), chunk):
        piece = text[i:i + chunk]
        if len(piece.encode("ascii").translate(None, _ASCII_STRAY)) != len(piece):
            return True
    return False


def from_text(text: str, file: str = STDIN_LABEL, encoding: str = "utf-8") -> SourceText:
    """Normalise already-decoded text (newlines, stray controls, final newline) into a SourceText."""
    if "\r" in text:                           # CRLF and lone CR: what re.sub("\r\n?") does, faster
        text = text.replace("\r\n", "\n")
        if "\r" in text:
            text = text.replace("\r", "\n")
    if not text.isascii() or _ascii_stray(text):
        text = _STRAY.sub(" ", text)
    had_final = text.endswith("\n") or not text
    if not had_final:
        text += "\n"
    src = SourceText(text, encoding, [], file, had_final)
    if not text.strip():
        src.diagnostics.append(Diagnostic("NC004", "error", "empty program: the file holds no NC blocks",
                                          file, 1, 1))
    return src


def is_regular_file(path: str | Path) -> bool:
    """A regular file (through symlinks): what a directory walk takes."""
    try:
        return stat.S_ISREG(os.stat(path).st_mode)
    except OSError:
        return False


def _too_large(path: str, size: int) -> SourceError:
    return SourceError(f"{path}: {size} bytes is more than the {max_input_bytes()} bytes "
                       "nctrans reads (README \"Limits\"; NCTRANS_MAX_INPUT_BYTES raises it)")


def max_input_bytes() -> int:
    """The input size limit: limits.MAX_INPUT_BYTES, or NCTRANS_MAX_INPUT_BYTES when set."""
    return limits.setting("MAX_INPUT_BYTES", limits.MAX_INPUT_BYTES)


def read_bytes(path: str | Path, limit: Optional[int] = None) -> bytes:
    """The file's bytes ('-' = standard input); SourceError with a readable message otherwise.
    Only regular files are read (a FIFO or device given by name is refused: it may never end),
    and none larger than the input limit. `limit`: read at most this many bytes (a head)."""
    cap = max_input_bytes()
    if str(path) == STDIN:
        return _read_stream(sys.stdin.buffer, "<stdin>", cap, limit)
    p = Path(path)
    try:
        with open(p, "rb", opener=_open_nonblocking) as fh:
            st = os.fstat(fh.fileno())
            if stat.S_ISDIR(st.st_mode):
                raise IsADirectoryError
            if not stat.S_ISREG(st.st_mode):
                kind = "a FIFO" if stat.S_ISFIFO(st.st_mode) else (
                    "a device" if stat.S_ISCHR(st.st_mode) or stat.S_ISBLK(st.st_mode) else "not a file")
                raise SourceError(f"{path}: is {kind}, not a regular file: nctrans reads program files "
                                  "(use '-' to read a stream from standard input)")
            if limit is not None:
                return _read_stream(fh, str(path), cap, limit)
            if st.st_size > cap:
                raise _too_large(str(path), st.st_size)
            data = fh.read()             # a regular file: one buffer of its size
            if len(data) > cap:          # it grew while being read
                raise _too_large(str(path), len(data))
            return data
    except FileNotFoundError:
        raise SourceError(f"{path}: no such file") from None
    except IsADirectoryError:
        raise SourceError(f"{path}: is a directory") from None
    except PermissionError:
        raise SourceError(f"{path}: permission denied") from None
    except OSError as e:
        raise SourceError(f"{path}: cannot read: {e.strerror or e}") from None


def _read_stream(fh, name: str, cap: int, limit: Optional[int]) -> bytes:
    """Read to the end in pieces (never one buffer of the limit's size), refusing more than
    `cap` bytes; with `limit`, only the first `limit` bytes."""
    want = cap + 1 if limit is None else limit
    parts: list[bytes] = []
    got = 0
    while got < want:
        piece = fh.read(min(1 << 20, want - got))
        if not piece:
            break
        parts.append(piece)
        got += len(piece)
    if limit is None and got > cap:
        raise _too_large(name, got)
    return parts[0] if len(parts) == 1 else b"".join(parts)


def _open_nonblocking(path, flags: int) -> int:
    """Open without blocking: opening a FIFO with no writer would otherwise hang before fstat
    can refuse it."""
    return os.open(path, flags | getattr(os, "O_NONBLOCK", 0))


def label_for(path: str | Path) -> str:
    """The name diagnostics use for a path ('<stdin>' for '-')."""
    return STDIN_LABEL if str(path) == STDIN else str(path)


def read_source(path: str | Path) -> SourceText:
    """Read and decode one program file ('-' = stdin). Raises SourceError only if it cannot be read."""
    return decode(read_bytes(path), label_for(path))


def read_head(path: str | Path, size: int) -> SourceText:
    """The first `size` bytes of a program, decoded, cut after their last whole line: what
    detection needs, without reading a whole (or endless) input."""
    data = read_bytes(path, limit=size)
    if len(data) == size:
        cut = data.rfind(b"\n")
        if cut > 0:
            data = data[:cut + 1]
    return decode(data, label_for(path))
