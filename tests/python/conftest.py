"""pytest setup for the report's tests: the package lives in scripts/sdf_report."""
import os
import sys

import pytest

HERE = os.path.dirname(os.path.abspath(__file__))
REPO = os.path.dirname(os.path.dirname(HERE))
sys.path.insert(0, os.path.join(REPO, "scripts"))
sys.path.insert(0, HERE)

from sdf_report import schema as run_schema  # noqa: E402


@pytest.fixture(scope="session")
def schema():
    return run_schema.load_schema()
