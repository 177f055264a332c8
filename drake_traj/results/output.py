"""The one writer for everything that leaves the process: run folders, benches and exports.

A folder's new content is written whole into a staging folder inside it, then moved into place
(renames, which need no space), the earlier content of the folder set aside until the last file
is in place and put back if one is not. A single file (an export, a manifest) is written to a
temporary sibling and ``os.replace``-d over its name. So a full disk, a lost permission or a
crash while writing leaves the earlier content as it was and no partial file behind.

A folder is claimed (:func:`claim`) before the work that fills it: the claim checks what can be
checked (writable, not another run's or bench's folder, free space roughly enough), and holds a
lock file, ``.drake-traj.lock``, that refuses a second writer and names it (pid and command). A
lock whose process has died is taken over. Files named ``.drake-traj-*`` are the writer's own
(the lock, staging folders, temporary files); a crash may leave them, and the next claim removes
them, except earlier content set aside by a replacement cut short, which it names instead. Symbolic links are never followed out of a folder: a file path that is a link is refused.
"""

from __future__ import annotations

import contextlib
import errno
import fcntl
import os
import shutil
import sys
import time
from pathlib import Path

from drake_traj.errors import Cause, DrakeTrajError

__all__ = ["FOLDER_KINDS", "LOCK", "Claim", "OutputError", "WriteError", "check_folder", "check_writable", "claim",
           "folder_kind", "locked", "working_folder", "write_file"]

LOCK = ".drake-traj.lock"
_OWN_PREFIX = ".drake-traj-"  # staging folders, set-aside content and temporary files
# The files that mark a folder as a run's or a bench's (a run's manifest first).
FOLDER_KINDS = {"run": ("run.json", "result.npz", "metrics.json"), "bench": ("bench.csv", "bench.md", "bench.png")}
MiB = 2**20


class OutputError(DrakeTrajError):
    """An output folder or file cannot be used: names it and the reason (found before writing)."""

    default_cause = Cause.OUTPUT


class WriteError(OutputError):
    """Writing failed part-way (disk full, permission, a folder removed meanwhile): names the file
    and the reason. Nothing partial is left and the earlier content is intact."""


def working_folder() -> Path:
    """The working folder; OutputError when it no longer exists (deleted or moved meanwhile)."""
    try:
        return Path(os.getcwd())
    except FileNotFoundError:
        raise OutputError("the working folder no longer exists (it was deleted or moved while in use), so relative "
                          "paths such as out/... mean nothing; cd to an existing folder and run again") from None


def _absolute(path: Path) -> Path:
    return path if path.is_absolute() else working_folder() / path


def _reason(error: OSError, path) -> str:
    """``error`` in words, naming ``path``."""
    words = {errno.ENOSPC: "no space left on device", errno.EDQUOT: "disk quota exceeded",
             errno.EACCES: "permission denied", errno.EPERM: "permission denied", errno.EROFS: "read-only file system",
             errno.ENOENT: "a folder was deleted or moved"}
    return f"{words.get(error.errno, error.strerror or str(error))} while writing {path}"


@contextlib.contextmanager
def _reported(path, what: str):
    """An OSError in the block as a :class:`WriteError` naming ``path``; ``what`` tells what was kept."""
    try:
        yield
    except OSError as error:
        raise WriteError(f"{_reason(error, path)}; {what}") from None


def folder_kind(directory: Path) -> str | None:
    """"run" or "bench" when ``directory`` holds one (:data:`FOLDER_KINDS`), else None."""
    for kind, signs in FOLDER_KINDS.items():
        if any(os.path.lexists(directory / name) for name in signs):
            return kind
    return None


def check_writable(directory: Path) -> None:
    """The folder exists as a writable folder, or can be created: not a file, not below a file."""
    directory = Path(directory)
    _absolute(directory)
    if directory.is_symlink() and not directory.exists():
        raise OutputError(f"output folder {directory} is a broken link or a loop of links")
    if directory.exists() and not directory.is_dir():
        raise OutputError(f"output folder {directory} is a file, not a folder")
    ancestor = directory
    while not ancestor.exists():
        if ancestor.parent == ancestor:
            break
        ancestor = ancestor.parent
    if ancestor.exists() and not ancestor.is_dir():
        raise OutputError(f"output folder {directory} cannot be created: {ancestor} is a file")
    if not os.access(ancestor, os.W_OK | os.X_OK):
        read_only = os.statvfs(ancestor).f_flag & os.ST_RDONLY
        raise OutputError(f"output folder {directory} cannot be written: {ancestor} is "
                          + ("on a read-only file system" if read_only else "not writable (permission denied)"))


def check_folder(directory, kind: str, *, overwrite: bool, earlier_files, options=("--out", "--overwrite")) -> Path:
    """Check ``directory`` before writing a ``kind`` ("run" or "bench") there, creating nothing:
    writable or creatable, not another kind's folder, not holding an earlier ``kind`` unless
    ``overwrite``, not holding files of anything else. ``earlier_files(directory)`` names the
    files of the earlier ``kind`` there; ``options`` name the folder and the overwrite option in
    messages. Raises :class:`OutputError`."""
    out, replace = options
    directory = Path(directory)
    try:
        check_writable(directory)
        if not directory.is_dir():
            return directory
        found = folder_kind(directory)
        if found is not None and found != kind:
            raise OutputError(f"output folder {directory} holds a {found} (its {_sign(directory, found)}); a {kind} "
                              f"is never written into a {found}'s folder: choose another {out}")
        owned = set()
        if found == kind:
            if not overwrite:
                raise OutputError(f"output folder {directory} holds an earlier {kind} (its {_sign(directory, kind)}); "
                                  f"choose another {out}, or pass {replace} to replace that {kind}")
            owned = set(earlier_files(directory)) | set(FOLDER_KINDS[kind])
        others = sorted(path.name for path in directory.iterdir()
                        if path.name not in owned and not path.name.startswith(_OWN_PREFIX) and path.name != LOCK)
        if others:
            raise OutputError(f"output folder {directory} holds files that are not a drake-traj {kind} "
                              f"({', '.join(others[:3])}{', ...' if len(others) > 3 else ''}); choose a new or "
                              "empty folder")
    except OSError as error:  # a name too long, a loop of links, ...
        raise OutputError(f"output folder {directory} cannot be used: {error.strerror}") from None
    return directory


def _sign(directory: Path, kind: str) -> str:
    return " and ".join(name for name in FOLDER_KINDS[kind] if os.path.lexists(directory / name))


def _check_space(directory: Path, needed: int) -> None:
    """OutputError when the file system of ``directory`` has less than ``needed`` bytes free."""
    if needed <= 0:
        return
    free = shutil.disk_usage(_absolute(directory)).free
    if free < needed:
        raise OutputError(f"not enough space for {directory}: about {needed / MiB:.1f} MiB are needed, "
                          f"{free / MiB:.1f} MiB are free there; free some space or choose another --out")


class _Lock:
    """An exclusive ``flock`` on ``directory/.drake-traj.lock``, which holds the holder's pid and
    command (for the message of a refused writer). The kernel releases it when its process dies,
    so a lock left by a dead process is taken over."""

    def __init__(self, directory: Path, command: str):
        path = _absolute(directory) / LOCK
        while True:
            fd = os.open(path, os.O_RDWR | os.O_CREAT | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
            try:
                fcntl.flock(fd, fcntl.LOCK_EX | fcntl.LOCK_NB)
            except BlockingIOError:
                holder = os.pread(fd, 4096, 0).decode(errors="replace").strip() or "a process that is starting"
                os.close(fd)
                raise OutputError(f"output folder {directory} is being written by another drake-traj process "
                                  f"({holder}); wait until it ends, or choose another --out") from None
            try:  # the holder before us may have removed the file we opened: lock the one in place
                same = os.stat(path, follow_symlinks=False).st_ino == os.fstat(fd).st_ino
            except FileNotFoundError:
                same = False
            if same:
                break
            os.close(fd)
        os.ftruncate(fd, 0)
        os.pwrite(fd, f"pid {os.getpid()}: {command}, since {time.strftime('%H:%M:%S')}\n".encode(), 0)
        self._fd, self._path = fd, path

    def release(self) -> None:
        if self._fd is not None:
            with contextlib.suppress(FileNotFoundError):
                self._path.unlink()
            os.close(self._fd)
            self._fd = None


def _clear_leftovers(directory: Path, absolute: Path) -> None:
    """Remove what a writer that died left in the folder (the caller holds its lock): staging
    folders, temporary files, and the earlier content it set aside once its new content was all
    in place. Content set aside by a replacement cut short while moving in (its staging folder
    not empty) is left for the user, and named (OutputError): which files are whose is unknown."""
    for aside in absolute.glob(f"{_OWN_PREFIX}replaced-*"):
        staging = absolute / aside.name.replace("replaced-", "staging-", 1)
        if staging.is_dir() and not staging.is_symlink() and any(staging.iterdir()):
            raise OutputError(f"output folder {directory}: a writer that died (pid {aside.name.rsplit('-', 1)[-1]}) "
                              f"was replacing its content: the earlier files are in {directory / aside.name}, the new "
                              f"ones not yet moved in are in {directory / staging.name}; put back what you want to keep "
                              "and remove those two folders")
    for leftover in absolute.glob(_OWN_PREFIX + "*"):
        shutil.rmtree(leftover) if leftover.is_dir() and not leftover.is_symlink() else leftover.unlink()


class Claim:
    """A folder claimed for one writer (:func:`claim`); :meth:`replace` writes its new content."""

    def __init__(self, directory: Path, kind: str, overwrite: bool, earlier_files, estimate: int, command: str,
                 options: tuple[str, str]):
        self.directory, self.kind = directory, kind
        self._earlier_files = earlier_files
        check_folder(directory, kind, overwrite=overwrite, earlier_files=earlier_files, options=options)
        absolute = _absolute(directory)
        self._created = not absolute.exists()
        try:
            absolute.mkdir(parents=True, exist_ok=True)
            self._lock = _Lock(directory, command)
        except OSError as error:
            self._remove_if_created()
            raise OutputError(f"output folder {directory} cannot be written: {_reason(error, directory / LOCK)}") from None
        try:
            _clear_leftovers(directory, absolute)
            check_folder(directory, kind, overwrite=overwrite, earlier_files=earlier_files, options=options)  # now ours
            _check_space(directory, estimate)
        except BaseException:
            self.release()
            raise

    def release(self) -> None:
        """Give the folder up; a folder the claim created and nothing was written into is removed."""
        self._lock.release()
        self._remove_if_created()

    def _remove_if_created(self) -> None:
        if self._created:
            with contextlib.suppress(OSError):
                self.directory.rmdir()  # only when empty

    def __enter__(self) -> "Claim":
        return self

    def __exit__(self, *exc) -> None:
        self.release()

    @contextlib.contextmanager
    def replace(self, *, keep_earlier: bool = False):
        """Yields a :class:`Staging`: the new content is written there; when the block ends
        without an error it replaces the folder's earlier content (files listed by
        ``earlier_files``), else it is removed and the earlier content stays. With
        ``keep_earlier``, the new files are added beside the earlier content instead, replacing
        only the files of the same names (a refusal's picture and manifest beside an earlier run).
        An OSError while writing is a :class:`WriteError` naming the file."""
        staging = Staging(self.directory, self.kind)
        try:
            yield staging
            earlier = []
            if keep_earlier:
                earlier = list(staging.files)
            elif folder_kind(self.directory) == self.kind:
                earlier = list(dict.fromkeys([*self._earlier_files(self.directory), *FOLDER_KINDS[self.kind]]))
            staging.commit(earlier)
        finally:
            staging.discard()


class Staging:
    """The new content of a claimed folder, written aside in ``.drake-traj-staging-<pid>`` inside it."""

    def __init__(self, directory: Path, kind: str):
        self.directory, self.kind = directory, kind
        self.path = directory / f"{_OWN_PREFIX}staging-{os.getpid()}"
        self.files: list[str] = []
        kept = self._kept()
        with _reported(directory, kept):
            self.path.mkdir()

    def _kept(self) -> str:
        return (f"nothing was written: the earlier {self.kind} in {self.directory} is intact"
                if folder_kind(self.directory) == self.kind else "nothing was written")

    def write(self, name: str, write) -> Path:
        """``write(path)`` writes the file ``name``; returns its final path in the folder."""
        if Path(name).name != name or name.startswith(_OWN_PREFIX):
            raise ValueError(f"{name!r} is not a plain file name")
        with _reported(self.directory / name, self._kept()):
            write(self.path / name)
            with open(self.path / name, "rb") as handle:  # on disk before the earlier content goes
                os.fsync(handle.fileno())
        if name not in self.files:
            self.files.append(name)
        return self.directory / name

    def commit(self, earlier: list[str]) -> None:
        """Set the earlier content aside, move the new files in (a manifest last, so a folder with
        one is complete), then delete what was set aside; put everything back on an error."""
        aside = self.directory / f"{_OWN_PREFIX}replaced-{os.getpid()}"
        moved, placed = [], []
        manifest = FOLDER_KINDS[self.kind][0]
        order = sorted(self.files, key=lambda name: name == manifest)
        with _reported(self.directory, self._kept()):
            try:
                aside.mkdir()
                for name in earlier:
                    if os.path.lexists(self.directory / name):
                        os.rename(self.directory / name, aside / name)
                        moved.append(name)
                for name in order:
                    os.rename(self.path / name, self.directory / name)
                    placed.append(name)
            except OSError:
                for name in placed:
                    with contextlib.suppress(OSError):
                        os.rename(self.directory / name, self.path / name)
                for name in moved:
                    with contextlib.suppress(OSError):
                        os.rename(aside / name, self.directory / name)
                raise
            finally:
                shutil.rmtree(aside, ignore_errors=True)

    def discard(self) -> None:
        shutil.rmtree(self.path, ignore_errors=True)


def claim(directory, kind: str, *, overwrite: bool = False, earlier_files=lambda directory: [], estimate: int = 0,
          command: str | None = None, options=("--out", "--overwrite")) -> Claim:
    """Claim ``directory`` for a ``kind`` ("run" or "bench") before the work that fills it:
    checked (:func:`check_folder`), created if missing, locked against a second writer, with
    about ``estimate`` bytes free. ``command`` names this process in a refused writer's message
    (default: its command line); ``options`` name the folder and the overwrite option in
    messages. Raises :class:`OutputError`; release with ``with`` or :meth:`Claim.release`."""
    command = command or " ".join(sys.argv)
    return Claim(Path(directory), kind, overwrite, earlier_files, estimate, command, tuple(options))


@contextlib.contextmanager
def locked(directory, command: str | None = None):
    """Hold the lock of the existing folder ``directory`` (as a :class:`Claim` does) in the block:
    for a file written into a run's folder (an export) while no other writer replaces it."""
    directory = Path(directory)
    try:
        lock = _Lock(directory, command or " ".join(sys.argv))
    except OSError as error:
        raise OutputError(f"folder {directory} cannot be written: {_reason(error, directory / LOCK)}") from None
    try:
        yield directory
    finally:
        lock.release()


def write_file(path, text: str | bytes, *, own_folder=None, what: str = "--out") -> Path:
    """Write ``text`` to the file ``path`` through a temporary sibling and ``os.replace``: the
    file is complete or untouched (the earlier one kept). Refused (:class:`OutputError`, before
    writing): a ``path`` that is a symbolic link or a folder, or lies in a run's or a bench's
    folder other than ``own_folder`` (whose claim the caller holds), or more than the free space.
    ``what`` names the path in messages."""
    path = Path(path)
    data = text.encode() if isinstance(text, str) else text
    absolute = _absolute(path)
    if absolute.is_symlink():
        raise OutputError(f"{what} {path} is a symbolic link (to {os.readlink(absolute)}): a link is never "
                          "written through; give the path of a plain file")
    if absolute.is_dir():
        raise OutputError(f"{what} {path} is a folder; give a file name")
    folder = absolute.parent
    if not folder.is_dir():
        raise OutputError(f"{what} {path}: the folder {path.parent} does not exist")
    kind = folder_kind(folder)
    if kind is not None and (own_folder is None or folder.resolve() != _absolute(Path(own_folder)).resolve()):
        raise OutputError(f"{what} {path} is in the folder of a {kind} ({path.parent}); a file is never written "
                          f"into another {kind}'s folder: choose another --out")
    _check_space(path.parent, len(data))
    temporary = folder / f"{_OWN_PREFIX}{path.name[:100]}-{os.getpid()}.tmp"
    try:
        with _reported(path, f"{'the earlier ' + path.name + ' is intact' if absolute.exists() else 'nothing was written'}"):
            descriptor = os.open(temporary, os.O_WRONLY | os.O_CREAT | os.O_EXCL | os.O_NOFOLLOW | os.O_CLOEXEC, 0o644)
            with os.fdopen(descriptor, "wb") as handle:
                handle.write(data)
                handle.flush()
                os.fsync(handle.fileno())
            os.replace(temporary, absolute)
    finally:  # the temporary file, where it was made (on a read-only folder unlinking fails too: the
        with contextlib.suppress(OSError):  # write's own error is the one to report)
            temporary.unlink()
    return path
