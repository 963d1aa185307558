"""The pip route end to end: a wheel of this build, installed into a fresh virtual environment,
passes the Python tests there, imported from the environment (not from build/python) and with
the environment's tools on PATH.

    pip_wheel_test.py SOURCE_DIR BUILD_DIR WORK_DIR     (CTest: pip_wheel; run with the python3
                                                        the module is built for)
    pip_wheel_test.py SOURCE_DIR BUILD_DIR WORK_DIR --portable
        (CTest: portable_wheel, registered with -DSDF_TEST_PORTABLE_WHEEL=ON) the portable wheel:
        configures WORK_DIR/build with -DSDF_WHEEL=ON (no tests, no benchmarks) and builds its
        sdf_package (the whole project again: about 10 minutes on 2 cores, less with ccache).

Every ELF file of the wheel is listed with its NEEDED entries (python/wheel_libs.py); for a
build tree configured with SDF_WHEEL=ON they must be glibc, libstdc++, libgcc or a library
bundled in sdf_lattices.libs/, and build_info() must say the wheel's optional parts are not built.

The wheel is built by setup.py with SDF_CMAKE_BUILD_DIR=BUILD_DIR: it packs the suite's own
build tree (its target sdf_package is already built: nothing is compiled twice), the route a
plain `pip install .` takes but for the configure step. No package index is reached
(--no-index, --no-build-isolation: setuptools, wheel, numpy and pytest come from Debian).
"""
import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

TOOLS = ["run-experiment", "sdf-query", "sdf-eval", "sdf-render", "sdf-sample"]


def run(cmd, **kwargs):
    print("+ " + " ".join(str(c) for c in cmd), flush=True)
    r = subprocess.run([str(c) for c in cmd], **kwargs)
    if r.returncode != 0:
        sys.exit(f"pip_wheel_test: exit {r.returncode} from {cmd[0]} {cmd[1] if len(cmd) > 1 else ''}")
    return r


def cache_value(build, key):
    for line in (build / "CMakeCache.txt").read_text().splitlines():
        if line.startswith(key + ":"):
            return line.split("=", 1)[1]
    return None


def configure_portable(source, build, main_build):
    """WORK_DIR/build: the portable wheel's tree, with the main build's compilers and launchers."""
    options = ["-DCMAKE_BUILD_TYPE=Release", "-DSDF_BUILD_TESTS=OFF", "-DSDF_BUILD_BENCHMARKS=OFF",
               "-DSDF_BUILD_PYTHON=ON", "-DSDF_WHEEL=ON", "-DSDF_BUILD_PEERS=OFF", f"-DPython3_EXECUTABLE={sys.executable}"]
    for key in ("CMAKE_CXX_COMPILER_LAUNCHER", "CMAKE_CUDA_COMPILER_LAUNCHER", "CMAKE_CUDA_ARCHITECTURES",
                "SDF_ENABLE_CUDA", "CMAKE_CUDA_COMPILER", "CMAKE_MAKE_PROGRAM"):
        value = cache_value(main_build, key)
        if value:
            options.append(f"-D{key}={value}")
    generator = ["-G", "Ninja"] if shutil.which("ninja") else []
    run(["cmake", "-S", source, "-B", build, *generator, *options], stdout=subprocess.DEVNULL)
    run(["cmake", "--build", build, "--target", "sdf_package", "-j", str(os.cpu_count() or 1)], stdout=subprocess.DEVNULL)


def main(source, build, work, portable=False):
    source, build, work = Path(source).resolve(), Path(build).resolve(), Path(work).resolve()
    shutil.rmtree(work / "venv", ignore_errors=True)
    shutil.rmtree(work / "wheels", ignore_errors=True)
    work.mkdir(parents=True, exist_ok=True)   # WORK_DIR/build (--portable) is kept: a rerun rebuilds only what changed
    if portable:
        configure_portable(source, work / "build", build)
        build = work / "build"
    venv = work / "venv"
    env = {k: v for k, v in os.environ.items() if k not in ("PYTHONPATH", "PYTHONHOME")}
    env.update(PIP_DISABLE_PIP_VERSION_CHECK="1", PIP_NO_INDEX="1", PIP_NO_CACHE_DIR="1", PYTHONDONTWRITEBYTECODE="1")

    run([sys.executable, "-m", "venv", "--system-site-packages", venv], env=env)
    python = venv / "bin" / "python"
    run([python, "-m", "pip", "wheel", "--no-build-isolation", "--no-deps", "-w", work / "wheels", source],
        env=dict(env, SDF_CMAKE_BUILD_DIR=str(build)), cwd=work)
    wheels = sorted((work / "wheels").glob("sdf_lattices-*.whl"))
    if len(wheels) != 1:
        sys.exit(f"pip_wheel_test: expected one sdf_lattices wheel in {work / 'wheels'}, found {[w.name for w in wheels]}")
    # Every ELF file's NEEDED list, read from the wheel; the policy holds for a portable build.
    sys.path.insert(0, str(source / "python"))
    import wheel_libs
    print(f"pip_wheel_test: {wheels[0].name}: {wheels[0].stat().st_size / 2**20:.1f} MiB", flush=True)
    policy_broken = wheel_libs.report(wheels[0])
    wheel_build = cache_value(build, "SDF_WHEEL") in ("ON", "TRUE", "1")
    if wheel_build and policy_broken:
        sys.exit("pip_wheel_test: the portable wheel needs libraries beyond glibc, libstdc++, libgcc and its own")
    run([python, "-m", "pip", "install", "--no-deps", wheels[0]], env=env, cwd=work)

    # The package comes from the environment, and says what the build found.
    probe = ("import json, sdf_lattices as s; "
             "print(json.dumps({'file': s.__file__, 'version': s.__version__, 'info': s.build_info()}))")
    found = json.loads(run([python, "-c", probe], env=env, cwd=work, capture_output=True, text=True).stdout)
    site = Path(run([python, "-c", "import sysconfig; print(sysconfig.get_paths()['platlib'])"], env=env, cwd=work,
                    capture_output=True, text=True).stdout.strip())
    if not Path(found["file"]).resolve().is_relative_to(site.resolve()):
        sys.exit(f"pip_wheel_test: sdf_lattices imported from {found['file']}, not from the environment's {site}")
    built = json.loads((build / "python" / "sdf_lattices" / "build_info.json").read_text())
    if found["info"] != built or found["version"] != built["version"]:
        sys.exit(f"pip_wheel_test: the installed build_info() {found['info']} differs from the build tree's {built}")
    if wheel_build:
        if not found["info"].get("portable_wheel"):
            sys.exit(f"pip_wheel_test: build_info() of the portable wheel lacks portable_wheel: true: {found['info']}")
        for part in ("mpi", "openvdb", "openimageio"):
            if found["info"]["optional"][part]["found"] or "not built" not in found["info"]["optional"][part]["detail"]:
                sys.exit(f"pip_wheel_test: build_info() of the portable wheel: {part} is {found['info']['optional'][part]}")
    for tool in TOOLS:
        path = venv / "bin" / tool
        if not os.access(path, os.X_OK):
            sys.exit(f"pip_wheel_test: the wheel did not install the tool {path}")
        out = run([path, "--version"], env=env, capture_output=True, text=True).stdout
        if not out.startswith(f"{tool} {found['version']} "):
            sys.exit(f"pip_wheel_test: {path} --version printed {out!r}")

    # The Python tests against the installed package and the installed tools, from outside the source.
    tests = source / "tests" / "python_module"
    test_env = dict(env, PATH=f"{venv / 'bin'}{os.pathsep}{env.get('PATH', '')}",
                    SDF_QUERY=str(venv / "bin" / "sdf-query"), SDF_EVAL=str(venv / "bin" / "sdf-eval"),
                    RUN_EXPERIMENT=str(venv / "bin" / "run-experiment"),
                    SDF_DATA_PATH=f"{source.parent / 'shared' / 'meshes'}:{source / 'data' / 'meshes'}")
    run([python, "-m", "pytest", "-q", "-p", "no:cacheprovider", "--color=no", tests], env=test_env, cwd=work)
    print(f"pip_wheel_test: {wheels[0].name} installed into {venv} passes the Python tests")


if __name__ == "__main__":
    if len(sys.argv) not in (4, 5) or (len(sys.argv) == 5 and sys.argv[4] != "--portable"):
        sys.exit(__doc__)
    main(*sys.argv[1:4], portable=len(sys.argv) == 5)
