"""python/wheel_libs.py, the portable wheel's ELF check, against readelf (binutils) on this
build's own ELF files: the same NEEDED lists and run paths, and the policy's verdict is exactly
"every NEEDED library beyond glibc, libstdc++ and libgcc that is not bundled".

    wheel_libs_test.py SOURCE_DIR BUILD_DIR     (CTest: wheel_libs)
"""
import re
import subprocess
import sys
from pathlib import Path


def readelf(path):
    out = subprocess.run(["readelf", "-d", str(path)], capture_output=True, text=True, check=True).stdout
    needed = re.findall(r"\(NEEDED\)\s+Shared library: \[(.+)\]", out)
    runpath = re.findall(r"\((?:RUNPATH|RPATH)\)\s+Library (?:runpath|rpath): \[(.*)\]", out)
    return needed, (runpath[0] if runpath else None)


def main(source, build):
    sys.path.insert(0, str(Path(source) / "python"))
    import wheel_libs
    build = Path(build)
    files = wheel_libs.elf_files(build / "bin")
    files.update({f"sdf_lattices/{n}": d for n, d in wheel_libs.elf_files(build / "python" / "sdf_lattices").items()})
    if not files:
        sys.exit(f"wheel_libs_test: no ELF files under {build}/bin")
    failures = []
    expected = []
    for name, data in files.items():
        path = build / "bin" / name if "/" not in name else build / "python" / name
        ours, theirs = wheel_libs.dynamic_entries(data, name), readelf(path)
        if ours != theirs:
            failures.append(f"{name}: wheel_libs reads {ours}, readelf {theirs}")
        expected += [f"{name} needs {lib}: neither a system library nor bundled in {wheel_libs.LIBS_DIR}/"
                     for lib in theirs[0] if lib not in wheel_libs.SYSTEM_LIBRARIES]
    if sorted(wheel_libs.problems(files)) != sorted(expected):
        failures.append(f"policy: {wheel_libs.problems(files)} != {expected}")
    # A bundled library is accepted only with a run path into sdf_lattices.libs (the stand-in
    # library's bytes are any ELF file's; only the problems of the tool itself are looked at).
    for name, data in files.items():
        needed, runpath = wheel_libs.dynamic_entries(data, name)
        extra = [lib for lib in needed if lib not in wheel_libs.SYSTEM_LIBRARIES]
        if not extra or (runpath or "").endswith(wheel_libs.LIBS_DIR):
            continue
        stand_in = {name: data, f"{wheel_libs.LIBS_DIR}/{extra[0]}": data}
        verdict = [p for p in wheel_libs.problems(stand_in) if p.startswith(name + " ") and extra[0] in p]
        if len(verdict) != 1 or "run path" not in verdict[0]:
            failures.append(f"{name}: a bundled {extra[0]} without a run path into {wheel_libs.LIBS_DIR}: {verdict}")
        break
    for f in failures:
        print("wheel_libs_test: " + f)
    if failures:
        sys.exit(1)
    print(f"wheel_libs_test: {len(files)} ELF files read as readelf reads them; the policy lists the same libraries")


if __name__ == "__main__":
    if len(sys.argv) != 3:
        sys.exit(__doc__)
    main(*sys.argv[1:])
