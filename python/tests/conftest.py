"""Paths of the repository the tests read (scenes, fixtures, examples)."""

import pathlib

import pytest

ROOT = pathlib.Path(__file__).resolve().parents[2]


@pytest.fixture
def root() -> pathlib.Path:
    """The repository's root (scenes/, tests/fixtures/)."""
    return ROOT
