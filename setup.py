"""The wheel of sdf_lattices: CMake builds the Python package and the command-line tools,
setuptools packs what `cmake --install` lays out (pyproject.toml has the metadata; README.md,
"Python", the commands).

    /usr/bin/python3 -m venv --system-site-packages .venv
    .venv/bin/pip install --no-build-isolation .

configures its own CMake tree under build/pip/ (no tests, no benchmarks; kept, so a second
install rebuilds only what changed), builds the target sdf_package, installs it into a staging
folder and packs
    sdf_lattices/   the package: the extension _core, the Python files, build_info.json
    bin/            the tools (run-experiment, sdf-query, ...), installed beside the
                    interpreter: on PATH in an activated virtual environment.
The optional parts (CUDA, MPI, OpenVDB, OpenImageIO) are used when CMake finds them; what was
found is printed (pip install -v shows it) and returned by sdf_lattices.build_info().

Environment:
    SDF_CMAKE_BUILD_DIR   a configured build tree to pack instead of configuring one: the
                          suite's wheel test passes its own build/, so that nothing is compiled
                          twice. Its Python module must be built for this interpreter's ABI.
    SDF_CMAKE_ARGS        extra configure options, e.g. "-DSDF_ENABLE_CUDA=OFF".
    SDF_WHEEL=1           the portable wheel (docs/python.md, "The portable wheel"): configures
                          with -DSDF_WHEEL=ON (under build/pip/.../cmake-wheel): no MPI, OpenVDB,
                          OpenImageIO or peers; libcrypto, GMP and the CUDA runtime static. The
                          libraries still shared (zlib) are copied into sdf_lattices.libs/, and
                          every ELF file is checked to need nothing else beyond glibc, libstdc++
                          and libgcc (python/wheel_libs.py). A build tree configured with
                          SDF_WHEEL=ON (SDF_CMAKE_BUILD_DIR) is packed the same way.
    CMAKE_BUILD_PARALLEL_LEVEL   build jobs (default: every core).
"""
import json
import os
import re
import shlex
import shutil
import subprocess
import sys
import sysconfig
from pathlib import Path

from setuptools import Extension, setup
from setuptools.command.build_ext import build_ext

ROOT = Path(__file__).resolve().parent
sys.path.insert(0, str(ROOT / "python"))
import wheel_libs  # noqa: E402  (python/wheel_libs.py: the portable wheel's libraries)
PIP_BUILD = "build/pip"   # setuptools' build folder (relative: setuptools wants it so)


def project_version():
    """The one version: CMakeLists.txt's project(... VERSION x.y.z)."""
    text = (ROOT / "CMakeLists.txt").read_text()
    match = re.search(r"project\(\s*sdf_lattices\s+VERSION\s+([0-9][0-9.]*)", text)
    if not match:
        sys.exit("setup.py: no `project(sdf_lattices VERSION x.y.z)` in CMakeLists.txt")
    return match.group(1)


def cmake_cache_value(build_dir, key):
    """A value of build_dir/CMakeCache.txt, or None."""
    for line in (build_dir / "CMakeCache.txt").read_text().splitlines():
        if line.startswith(key + ":"):
            return line.split("=", 1)[1]
    return None


def interpreter_problem():
    """Why this interpreter cannot build the extension, or None."""
    try:
        import numpy  # noqa: F401
    except ImportError:
        return "it cannot import numpy"
    if not (Path(sysconfig.get_paths()["include"]) / "Python.h").exists():
        return f"it has no headers ({sysconfig.get_paths()['include']}/Python.h)"
    return None


def run(cmd, **kwargs):
    print("setup.py: " + " ".join(shlex.quote(str(c)) for c in cmd), flush=True)
    subprocess.run([str(c) for c in cmd], check=True, **kwargs)


def describe(info):
    """One line per optional part of build_info.json."""
    lines = [f"sdf_lattices {info['version']} ({info['build_type']}, CPU target {info['cpu_target']})"]
    for name, part in info["optional"].items():
        lines.append(f"  {name:<12} {'yes' if part['found'] else 'no ':<4} {part['detail']}")
    return "\n".join(lines)


class CMakeExtension(Extension):
    """The extension sdf_lattices._core, built by CMake (no sources for setuptools)."""

    def __init__(self, name):
        super().__init__(name, sources=[])


class CMakeBuild(build_ext):
    """Configures (or reuses) a CMake tree, builds sdf_package, installs it into a staging
    folder and copies the package into the wheel's tree and the tools into its data (bin/)."""

    def build_extension(self, ext):
        env = dict(os.environ)
        if Path("/usr/local/cuda/bin/nvcc").exists():   # where scripts/build looks for nvcc too
            env["PATH"] = env.get("PATH", "") + os.pathsep + "/usr/local/cuda/bin"
        build_dir = self.cmake_tree(env)
        jobs = os.environ.get("CMAKE_BUILD_PARALLEL_LEVEL") or str(os.cpu_count() or 1)
        run(["cmake", "--build", build_dir, "--target", "sdf_package", "-j", jobs], env=env)

        stage = Path(self.build_temp).resolve() / "stage"
        shutil.rmtree(stage, ignore_errors=True)
        run(["cmake", "--install", build_dir, "--prefix", stage], env=env, stdout=subprocess.DEVNULL)
        package = stage / cmake_cache_value(build_dir, "SDF_PYTHON_INSTALL_DIR") / "sdf_lattices"
        info = json.loads((package / "build_info.json").read_text())
        print(describe(info), flush=True)

        # The package: CMake's install (extension, Python files, build_info.json) over build_py's copy.
        target = Path(self.get_ext_fullpath(ext.name))
        if not (package / target.name).exists():
            built = sorted(p.name for p in package.glob("_core*"))
            raise SystemExit(f"setup.py: {build_dir} built {built}, but this interpreter ({sys.executable}) "
                             f"imports {target.name}: configure it for this Python (-DPython3_EXECUTABLE={sys.executable})")
        target.parent.mkdir(parents=True, exist_ok=True)
        for item in package.iterdir():
            shutil.copy2(item, target.parent / item.name)
        # The tools: installed into the environment's bin/ (a wheel's .data/data/bin).
        tools = sorted(str(p) for p in (stage / "bin").iterdir())
        if not tools:
            raise SystemExit(f"setup.py: `cmake --install {build_dir}` installed no tools")
        self.distribution.data_files = [("bin", tools)]
        # (A portable build's bundled libraries, left in setuptools' build folder, are no part of another wheel.)
        shutil.rmtree(Path(self.build_lib).resolve() / wheel_libs.LIBS_DIR, ignore_errors=True)
        if cmake_cache_value(build_dir, "SDF_WHEEL") in ("ON", "TRUE", "1"):
            self.bundle_libraries(target, [Path(t) for t in tools])

    def bundle_libraries(self, module, tools):
        """The portable wheel: the shared libraries beyond glibc and the C++ runtime go into
        sdf_lattices.libs/ beside the package (the run paths CMake set point there); then every
        ELF file is checked."""
        libs = Path(self.build_lib).resolve() / wheel_libs.LIBS_DIR
        copied = wheel_libs.bundle([module, *tools], libs)
        print(f"setup.py: bundled into {wheel_libs.LIBS_DIR}/: {' '.join(copied) or 'nothing'}", flush=True)
        files = {f"sdf_lattices/{module.name}": module.read_bytes()}
        files.update({f"bin/{t.name}": t.read_bytes() for t in tools})
        files.update({f"{wheel_libs.LIBS_DIR}/{p.name}": p.read_bytes() for p in libs.glob("*")})
        found = wheel_libs.problems(files)
        if found:
            raise SystemExit("setup.py: the portable wheel would need libraries of this machine:\n  " + "\n  ".join(found))

    def cmake_tree(self, env):
        """SDF_CMAKE_BUILD_DIR as it is, or build/pip/.../cmake configured for this interpreter."""
        given = os.environ.get("SDF_CMAKE_BUILD_DIR")
        if given:
            build_dir = Path(given).resolve()
            if not (build_dir / "CMakeCache.txt").exists():
                raise SystemExit(f"setup.py: SDF_CMAKE_BUILD_DIR={given} is not a configured CMake build tree (no CMakeCache.txt)")
            print(f"setup.py: packing the existing build tree {build_dir} (SDF_CMAKE_BUILD_DIR)", flush=True)
            return build_dir
        problem = interpreter_problem()
        if problem:
            raise SystemExit(f"setup.py: {sys.executable} cannot build the module: {problem}. On Debian 12, "
                             "install python3-dev python3-numpy pybind11-dev (scripts/install-deps) and build in a "
                             "virtual environment of /usr/bin/python3 made with --system-site-packages (README.md, \"Python\")")
        portable = os.environ.get("SDF_WHEEL", "") not in ("", "0")
        build_dir = Path(self.build_temp).resolve() / ("cmake-wheel" if portable else "cmake")
        options = ["-DCMAKE_BUILD_TYPE=Release", "-DSDF_BUILD_TESTS=OFF", "-DSDF_BUILD_BENCHMARKS=OFF",
                   "-DSDF_BUILD_PYTHON=ON", f"-DPython3_EXECUTABLE={sys.executable}"]
        if portable:
            options += ["-DSDF_WHEEL=ON", "-DSDF_BUILD_PEERS=OFF"]
        options += shlex.split(os.environ.get("SDF_CMAKE_ARGS", ""))
        generator = ["-G", "Ninja"] if shutil.which("ninja") and not (build_dir / "CMakeCache.txt").exists() else []
        run(["cmake", "-S", ROOT, "-B", build_dir, *generator, *options], env=env)
        return build_dir


Path(ROOT / PIP_BUILD).mkdir(parents=True, exist_ok=True)   # egg_info wants egg_base to exist
setup(
    version=project_version(),
    packages=["sdf_lattices"],
    package_dir={"": "python"},
    ext_modules=[CMakeExtension("sdf_lattices._core")],
    cmdclass={"build_ext": CMakeBuild},
    options={"build": {"build_base": PIP_BUILD}, "egg_info": {"egg_base": PIP_BUILD}},
    zip_safe=False,
)
