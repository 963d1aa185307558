"""scripts/user-wait end to end on the CPU with the build's tools and module (CTest passes
SDF_BUILD_DIR): the sampling rows on --backend cpu at small sizes, the experiment row, and the
render row on a 12-triangle box; the record is read back by the report's reader and its
counts are the lattices'. No timing is asserted (only that the times were recorded). The GPU
rows' "not run" and the peers' rows are tested in tests/python/test_user_wait.py."""
import json
import os
import subprocess
import sys

import pytest

REPO = os.path.dirname(os.path.dirname(os.path.dirname(os.path.abspath(__file__))))
sys.path.insert(0, os.path.join(REPO, "scripts"))

from sdf_report import user_wait  # noqa: E402

BOX = [(-1, -1, -1), (1, -1, -1), (1, 1, -1), (-1, 1, -1), (-1, -1, 1), (1, -1, 1), (1, 1, 1), (-1, 1, 1)]
BOX_FACES = [(0, 2, 1), (0, 3, 2), (4, 5, 6), (4, 6, 7), (0, 1, 5), (0, 5, 4),
             (1, 2, 6), (1, 6, 5), (2, 3, 7), (2, 7, 6), (3, 0, 4), (3, 4, 7)]


def have_mesh(name):
    """Whether the tools find `name` (scripts/user-wait's search: $SDF_DATA_PATH, data/meshes,
    ../shared/meshes)."""
    dirs = [d for d in os.environ.get("SDF_DATA_PATH", "").split(os.pathsep) if d]
    dirs += [os.path.join(REPO, "data", "meshes"), os.path.join(REPO, "..", "shared", "meshes")]
    return any(os.path.isfile(os.path.join(d, name)) for d in dirs)


@pytest.mark.skipif("SDF_BUILD_DIR" not in os.environ, reason="needs the build directory (CTest passes it)")
def test_user_wait_measures_the_cpu_rows_and_names_the_rest(tmp_path):
    missing = [m for m in ("dragon.obj", "dragon-legacy.obj") if not have_mesh(m)]
    if missing:
        pytest.skip("the rows' meshes are not on this machine (scripts/fetch-meshes): " + ", ".join(missing))
    box = tmp_path / "box.obj"
    box.write_text("".join("v %d %d %d\n" % v for v in BOX) + "".join("f %d %d %d\n" % (a + 1, b + 1, c + 1)
                                                                        for a, b, c in BOX_FACES))
    rows = "sample_1024,python_sample,python_query_16m,query_1_point,experiment,render"
    r = subprocess.run([sys.executable, os.path.join(REPO, "scripts", "user-wait"), "--build", os.environ["SDF_BUILD_DIR"],
                        "--rows", rows, "--backend", "cpu", "--resolution", "16", "--python-resolution", "8",
                        "--render-mesh", str(box), "--query-calls", "50", "--query-points", "1000", "--results", str(tmp_path / "results" / "user_wait")],
                       capture_output=True, text=True)
    assert r.returncode == 0, r.stdout + r.stderr
    (path,) = (tmp_path / "results" / "user_wait").glob("*/user_wait.json")
    run = user_wait.read_run(str(path))
    by_id = {row["id"]: row for row in run["rows"]}
    assert list(by_id) == rows.split(",")
    for name in ("sample_1024", "python_sample", "python_query_16m", "query_1_point", "experiment", "render"):
        row = by_id[name]
        assert row["status"] == "measured", row
        assert row["wall_seconds"] > 0
    assert by_id["sample_1024"]["details"]["points"] == 16 ** 3 and by_id["sample_1024"]["details"]["backend"] == "cpu"
    assert by_id["python_sample"]["details"]["points"] == 8 ** 3
    assert by_id["python_query_16m"]["details"]["points"] == 1000 and by_id["python_query_16m"]["kernel_seconds"] is None
    assert by_id["experiment"]["details"]["points"] == 48 ** 3 and by_id["experiment"]["details"]["method"] == "bvh"
    assert by_id["render"]["details"]["method"] == "bvh" and by_id["render"]["kernel_seconds"] > 0
    assert by_id["query_1_point"]["kernel_seconds"] is None and by_id["query_1_point"]["details"]["calls"] == 50
    assert run["machine"]["cpu"] and run["commit"]
    with open(path) as f:
        assert json.load(f)["format"] == "sdf-user-wait"
