"""build_info(): what this build of sdf_lattices found of its optional parts."""
import json
import os

_PATH = os.path.join(os.path.dirname(os.path.abspath(__file__)), "build_info.json")


def build_info():
    """build_info() -> dict

    What the build that made this package found, as CMake recorded it (build_info.json beside
    the package's files; cmake/Packaging.cmake writes it): version, build_type, cpu_target,
    compiler, python, and optional: for each of cuda, mpi, openvdb and openimageio a dict
    {"found": bool, "detail": str}: the version found, or why it is missing and which Debian
    packages add it; cuda's dict also has "architectures", the CUDA architectures compiled in
    (CMake's names: "90-real" is machine code for sm_90, "90-virtual" PTX that newer GPUs
    compile when they load it). Whether a GPU is present now is cuda_available()'s answer.
    """
    try:
        with open(_PATH, encoding="utf-8") as f:
            return json.load(f)
    except OSError as e:
        raise RuntimeError(f"{_PATH}: cannot read the build's description ({e.strerror}); "
                           "rebuild the package (cmake --build, or pip install)") from None
