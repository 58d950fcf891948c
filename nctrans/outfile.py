"""Where `convert` writes: atomically where that is safe, never replacing what is not a file.

An output is written in pieces (a streamed conversion writes as it goes) and only becomes visible
on commit(); discard() (an error, a refusal, SIGINT or SIGTERM) leaves no temporary file behind.

What stands at the output path decides how (README "Limits and safety"):
- nothing, or a regular file: a temporary file in the same directory, renamed over the path on
  commit, so a reader never sees half a program and a failure keeps the old file;
- a symbolic link: the same, at the file the link points to (the link stays a link);
- a device, FIFO or socket (/dev/null, /dev/stdout, a named pipe): written straight through. A
  rename would replace the node itself (as root, `-o /dev/null` would replace the system's);
- standard output (no path): spooled to an anonymous temporary file and copied out on commit,
  so a refused conversion prints nothing and a long one holds no text in memory.
"""
from __future__ import annotations

import os
import shutil
import stat
import sys
import tempfile
from pathlib import Path
from typing import IO, Optional


def kind_of(path: Path) -> str:
    """'new', 'file' or 'special' (device, FIFO, socket) for what the path leads to; 'dir' for a
    directory."""
    try:
        mode = os.stat(path).st_mode          # follows symlinks: the link's target decides
    except FileNotFoundError:
        return "new"
    if stat.S_ISDIR(mode):
        return "dir"
    return "file" if stat.S_ISREG(mode) else "special"


class OutputFile:
    """One output. write(text) any number of times, then commit() or discard()."""

    def __init__(self, path: Optional[Path]):
        self.path = path
        self._fh: Optional[IO[str]] = None
        self._tmp: Optional[str] = None
        self._through = False
        self._done = False

    def _open(self) -> IO[str]:
        if self.path is None:
            self._fh = tempfile.TemporaryFile("w+", encoding="utf-8", newline="")
        elif kind_of(self.path) == "special":
            self._through = True
            self._fh = open(self.path, "w", encoding="utf-8", newline="")
        else:
            target = Path(os.path.realpath(self.path))      # through a symlink to its file
            target.parent.mkdir(parents=True, exist_ok=True)
            fd, self._tmp = tempfile.mkstemp(prefix=f".{target.name}.", suffix=".tmp",
                                             dir=target.parent)
            self._fh = os.fdopen(fd, "w", encoding="utf-8", newline="")
        return self._fh

    def write(self, text: str) -> None:
        (self._fh or self._open()).write(text)

    def commit(self) -> None:
        """Make the output visible: rename the temporary file, or copy the spool to stdout."""
        fh = self._fh or self._open()
        self._done = True
        if self.path is None:
            fh.seek(0)
            shutil.copyfileobj(fh, sys.stdout, 1 << 20)
            sys.stdout.flush()
            fh.close()
            return
        fh.flush()
        if self._through:
            fh.close()
            return
        os.fsync(fh.fileno())
        fh.close()
        umask = os.umask(0)
        os.umask(umask)
        os.chmod(self._tmp, 0o666 & ~umask)
        os.replace(self._tmp, os.path.realpath(self.path))
        self._tmp = None

    def discard(self) -> None:
        """Drop what was written (nothing becomes visible); safe to call more than once."""
        if self._fh is not None and not self._fh.closed:
            try:
                self._fh.close()
            except OSError:
                pass
        if self._tmp is not None:
            try:
                os.unlink(self._tmp)
            except OSError:
                pass
            self._tmp = None

    def reset(self) -> None:
        """Discard what was written and start again empty."""
        self.discard()
        self.__init__(self.path)

    def __enter__(self) -> "OutputFile":
        return self

    def __exit__(self, *exc) -> None:
        self.discard()

