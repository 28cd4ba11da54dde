"""Shared fixtures: a known four-bar whose coupler provides textbook guidance positions."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

SEAT = Path(__file__).resolve().parents[2] / "examples" / "seat" / "mechanize.toml"

GROUND_A = np.array([0.0, 0.0])
GROUND_D = np.array([4.0, 0.0])
CRANK, COUPLER, ROCKER = 1.5, 3.2, 3.0


def coupler_pose(
    phi: float,
    *,
    crank: float = CRANK,
    coupler: float = COUPLER,
    rocker: float = ROCKER,
    ground_d: np.ndarray = GROUND_D,
) -> np.ndarray:
    """Pose ``(x, y, angle)`` of the coupler frame (origin at B, x towards C) at crank angle ``phi``."""
    b = GROUND_A + crank * np.array([np.cos(phi), np.sin(phi)])
    d = float(np.linalg.norm(ground_d - b))
    towards = np.arctan2(*(ground_d - b)[::-1])
    gamma = np.arccos((coupler**2 + d * d - rocker**2) / (2 * coupler * d))
    c = b + coupler * np.array([np.cos(towards + gamma), np.sin(towards + gamma)])
    return np.array([b[0], b[1], np.arctan2(*(c - b)[::-1])])


@pytest.fixture
def four_bar_poses() -> np.ndarray:
    """Five coupler poses of the four-bar A(0,0)-B-C-D(4,0) at crank angles 40..110 degrees."""
    return np.array([coupler_pose(p) for p in np.radians([40.0, 55.0, 70.0, 90.0, 110.0])])


@pytest.fixture(scope="session")
def seat_mechanized(tmp_path_factory: pytest.TempPathFactory) -> tuple[object, object, Path]:
    """The bundled seat synthesised and mechanized with its problem file's options, written to a folder."""
    from linkwork.io.problem import load_problem
    from linkwork.mechanization import mechanize, write_mechanization
    from linkwork.synthesis import synthesize

    result = synthesize(load_problem(SEAT))
    found = mechanize(result)
    folder = tmp_path_factory.mktemp("seat")
    write_mechanization(found, folder)
    return result, found, folder
