"""Typed, range-checked command-line values: a bad value ends the command with exit 2 and one line naming the
option, before anything runs."""

from __future__ import annotations

import argparse
import math
import os
import sys
import tempfile
from collections.abc import Callable
from pathlib import Path
from typing import NoReturn

MAX_DURATION_S = 86_400.0  # one day of simulated time
MAX_SEED = 2**32 - 1  # numpy's seed range


class OneLineParser(argparse.ArgumentParser):
    """An ArgumentParser whose errors are one line on stderr (exit 2), without the usage block."""

    def error(self, message: str) -> NoReturn:
        print(f"{self.prog}: error: {message}", file=sys.stderr)
        sys.exit(2)


def number(lo: float, hi: float, *, lo_open: bool = False, unit: str = "") -> Callable[[str], float]:
    """A finite float in [lo, hi] ((lo, hi] when ``lo_open``)."""

    def parse(text: str) -> float:
        try:
            x = float(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not a number") from None
        if not math.isfinite(x) or x > hi or x < lo or (lo_open and x == lo):
            bound = f"{'(' if lo_open else '['}{lo:g}, {hi:g}]"
            raise argparse.ArgumentTypeError(f"{text} is outside {bound}{' ' + unit if unit else ''}")
        return x

    return parse


def integer(lo: int, hi: int) -> Callable[[str], int]:
    """An integer in [lo, hi]."""

    def parse(text: str) -> int:
        try:
            n = int(text)
        except ValueError:
            raise argparse.ArgumentTypeError(f"'{text}' is not an integer") from None
        if not lo <= n <= hi:
            raise argparse.ArgumentTypeError(f"{n} is outside [{lo}, {hi}]")
        return n

    return parse


def _creatable_dir(path: Path) -> str | None:
    """Why ``path`` cannot be (or become) a writable folder; None if it can. Tried, not guessed from permission
    bits (which say nothing to root, nor of read-only mounts and pseudo-filesystems): the missing folders are made
    and a temporary file is written in it; what the trial made is removed again."""
    p = path.expanduser().absolute()
    if p.exists() and not p.is_dir():
        return f"{path} exists and is not a folder"
    missing: list[Path] = []
    parent = p
    while not parent.exists():
        missing.append(parent)
        parent = parent.parent
    if not parent.is_dir():
        return f"{parent} is not a folder"
    made: list[Path] = []
    try:
        for folder in reversed(missing):
            folder.mkdir()
            made.append(folder)
        with tempfile.TemporaryFile(dir=p):
            pass
    except OSError as exc:
        return f"cannot write into {path}: {exc.strerror or exc}"
    finally:
        for folder in reversed(made):
            try:
                folder.rmdir()
            except OSError:
                pass
    return None


def out_dir(text: str) -> Path:
    """An output folder that exists and is writable, or can be created."""
    why = _creatable_dir(Path(text))
    if why:
        raise argparse.ArgumentTypeError(why)
    return Path(text)


def out_file(text: str) -> str:
    """A file to write: not a folder, in a folder that exists or can be created, and writable."""
    p = Path(text)
    if p.is_dir():
        raise argparse.ArgumentTypeError(f"{text} is a folder")
    why = _creatable_dir(p.expanduser().absolute().parent)
    if why:
        raise argparse.ArgumentTypeError(why)
    if p.exists() and not os.access(p, os.W_OK):
        raise argparse.ArgumentTypeError(f"{text} is not writable")
    return text


def in_file(text: str) -> str:
    """A readable file."""
    p = Path(text)
    if not p.is_file():
        raise argparse.ArgumentTypeError(f"{text}: no such file")
    if not os.access(p, os.R_OK):
        raise argparse.ArgumentTypeError(f"{text} is not readable")
    return text


def in_dir(text: str) -> str:
    """An existing folder."""
    if not Path(text).is_dir():
        raise argparse.ArgumentTypeError(f"{text}: no such folder")
    return text


duration_s = number(0.0, MAX_DURATION_S, lo_open=True, unit="s")
seed = integer(0, MAX_SEED)
port = integer(1, 65535)
rate_hz = number(0.0, 1000.0, lo_open=True, unit="Hz")
mass_kg = number(0.0, 1000.0, lo_open=True, unit="kg")
scale = number(0.0, 1e6, lo_open=True)
speed = number(0.0, 100.0, lo_open=True)
turn_rate_rad_s = number(-3.0, 3.0, unit="rad/s")
noise_factor = number(0.0, 20.0)  # times the sensor model's default noise
