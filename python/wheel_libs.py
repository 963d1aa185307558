"""The portable wheel's shared libraries (docs/python.md, "The portable wheel"): what each ELF
file of a wheel needs (its DT_NEEDED entries, read from the file itself), the libraries that
setup.py bundles into sdf_lattices.libs/ (as auditwheel does, without renaming them), and the
check that nothing else is needed beyond glibc, libstdc++ and libgcc.

    python3 python/wheel_libs.py WHEEL_OR_FOLDER     prints every ELF's size, NEEDED and run
                                                     path; exits 1 if one needs a library that is
                                                     neither a system one nor bundled

Used by setup.py (SDF_WHEEL=1), tests/packaging/pip_wheel_test.py and
scripts/device/wheel-check.sh. No third-party module: it runs in any python3.
"""
import shutil
import struct
import subprocess
import sys
import zipfile
from pathlib import Path

# glibc, the C++ runtime and the dynamic loader: on every Linux a wheel installs on (the
# manylinux policy's core). The NVIDIA driver's libcuda is dlopened by the static CUDA runtime.
SYSTEM_LIBRARIES = frozenset({
    "libc.so.6", "libm.so.6", "libdl.so.2", "libpthread.so.0", "librt.so.1", "ld-linux-x86-64.so.2",
    "libstdc++.so.6", "libgcc_s.so.1",
})
LIBS_DIR = "sdf_lattices.libs"

_DT_NEEDED, _DT_RPATH, _DT_RUNPATH = 1, 15, 29
_SHT_DYNAMIC = 6


def is_elf(data):
    return data[:4] == b"\x7fELF"


def dynamic_entries(data, name="ELF file"):
    """(NEEDED list, run path or None) of a 64-bit little-endian ELF file's bytes."""
    if not is_elf(data):
        raise ValueError(f"{name}: not an ELF file")
    if data[4] != 2 or data[5] != 1:
        raise ValueError(f"{name}: not a 64-bit little-endian ELF file (class {data[4]}, data {data[5]})")
    shoff, = struct.unpack_from("<Q", data, 0x28)
    shentsize, shnum = struct.unpack_from("<HH", data, 0x3A)
    if shoff == 0 or shoff + shentsize * shnum > len(data):
        raise ValueError(f"{name}: section headers outside the file")
    sections = [struct.unpack_from("<IIQQQQIIQQ", data, shoff + i * shentsize) for i in range(shnum)]
    dynamic = [s for s in sections if s[1] == _SHT_DYNAMIC]
    if not dynamic:
        return [], None    # statically linked
    _, _, _, _, offset, size, link, _, _, entsize = dynamic[0]
    strtab_offset, strtab_size = sections[link][4], sections[link][5]

    def string(index):
        if index >= strtab_size:
            raise ValueError(f"{name}: dynamic string index {index} outside its table ({strtab_size} bytes)")
        end = data.index(b"\0", strtab_offset + index)
        return data[strtab_offset + index:end].decode()

    needed, runpath = [], None
    for position in range(offset, offset + size, entsize or 16):
        tag, value = struct.unpack_from("<qQ", data, position)
        if tag == 0:
            break
        if tag == _DT_NEEDED:
            needed.append(string(value))
        elif tag in (_DT_RPATH, _DT_RUNPATH):
            runpath = string(value)
    return needed, runpath


def elf_files(where):
    """{name: bytes} of every ELF file in a wheel (.whl) or under a folder."""
    where = Path(where)
    found = {}
    if where.suffix == ".whl":
        with zipfile.ZipFile(where) as wheel:
            for info in wheel.infolist():
                with wheel.open(info) as f:
                    head = f.read(4)
                if is_elf(head):
                    found[info.filename] = wheel.read(info)
    else:
        for path in sorted(p for p in where.rglob("*") if p.is_file() and not p.is_symlink()):
            with open(path, "rb") as f:
                if is_elf(f.read(4)):
                    found[str(path.relative_to(where))] = path.read_bytes()
    return found


def problems(files):
    """What breaks the policy: every NEEDED is a system library or a file of sdf_lattices.libs/,
    and an ELF that needs a bundled library has a run path into sdf_lattices.libs."""
    bundled = {Path(n).name for n in files if Path(n).parent.name == LIBS_DIR}
    found = []
    for name, data in files.items():
        needed, runpath = dynamic_entries(data, name)
        for library in needed:
            if library in SYSTEM_LIBRARIES:
                continue
            if library not in bundled:
                found.append(f"{name} needs {library}: neither a system library nor bundled in {LIBS_DIR}/")
            elif Path(name).parent.name != LIBS_DIR and not (runpath or "").rstrip("/").endswith(LIBS_DIR):
                found.append(f"{name} needs the bundled {library} but its run path is {runpath!r}, not .../{LIBS_DIR}")
    return found


def bundle(elfs, libs_dir):
    """Copies into libs_dir every library the ELF files need beyond the system ones (resolved by
    ldd, where this machine's loader finds them), and what those need in turn. Returns the names."""
    libs_dir = Path(libs_dir)
    todo, copied = [Path(e) for e in elfs], []
    while todo:
        elf = todo.pop()
        needed, _ = dynamic_entries(elf.read_bytes(), str(elf))
        wanted = [n for n in needed if n not in SYSTEM_LIBRARIES and n not in copied]
        if not wanted:
            continue
        resolved = {}
        for line in subprocess.run(["ldd", str(elf)], capture_output=True, text=True).stdout.splitlines():
            parts = line.split()
            if len(parts) >= 3 and parts[1] == "=>" and parts[2].startswith("/"):
                resolved[parts[0]] = Path(parts[2])
        for library in wanted:
            if library not in resolved:
                raise SystemExit(f"wheel_libs: {elf} needs {library}, which this machine's loader does not find "
                                 "(ldd): install it or add its folder to LD_LIBRARY_PATH")
            libs_dir.mkdir(parents=True, exist_ok=True)
            shutil.copy2(resolved[library].resolve(), libs_dir / library)
            copied.append(library)
            todo.append(libs_dir / library)
    return copied


def report(where):
    """One line per ELF file: its size, NEEDED and run path; then the policy's verdict."""
    files = elf_files(where)
    for name, data in files.items():
        needed, runpath = dynamic_entries(data, name)
        print(f"{name} ({len(data) / 2**20:.1f} MiB)\n  NEEDED {' '.join(needed) or '(none)'}"
              + (f"\n  RUNPATH {runpath}" if runpath else ""))
    found = problems(files)
    for p in found:
        print("wheel_libs: " + p)
    if not found:
        print(f"wheel_libs: {len(files)} ELF files need nothing beyond glibc, libstdc++, libgcc and {LIBS_DIR}/")
    return 1 if found else 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    if Path(sys.argv[1]).suffix == ".whl":
        print(f"{sys.argv[1]}: {Path(sys.argv[1]).stat().st_size / 2**20:.1f} MiB")
    sys.exit(report(sys.argv[1]))
