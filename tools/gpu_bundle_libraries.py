#!/usr/bin/env python3
"""Which shared libraries the GPU bundle carries, and stand-in libraries for the rest (tools/gpu_bundle.sh).

OpenImageIO 2.4 on Debian 12 loads ffmpeg, OpenCV, OpenVDB, DCMTK, LibRaw, libheif, OpenColorIO, libtiff, ... for
image formats refray never reads or writes on the GPU machine (it writes PNG and EXR). Their packages and what
they load come to about 120 MiB of .debs, more than a device call carries. So the bundle carries the libraries
refray really uses (Embree, oneTBB, OpenImageIO, OpenEXR, libpng, libjpeg, FreeType, ...) and, for each library
in STAND_INS, a stand-in with the same soname that defines exactly the symbols (and symbol versions) the carried
libraries import from it. Each stand-in function aborts with a message naming itself, so a stand-in that is ever called
says so instead of misbehaving. On the GPU machine tools/gpu_run.sh links a stand-in only where the machine has no
library of that soname.

  gpu_bundle_libraries.py BINARY OUTDIR  ->  OUTDIR/carried.txt (soname path, one a line) and OUTDIR/stand-ins/*.so
"""
import os
import re
import subprocess
import sys

# Format plug-ins and colour management OpenImageIO links but refray's PNG/EXR output never calls.
STAND_INS = {
    "libopencv_core.so.406", "libopencv_imgproc.so.406", "libopencv_videoio.so.406",
    "libdcmimage.so.17", "libdcmimgle.so.17", "libdcmdata.so.17", "liboflog.so.17", "libofstd.so.17",
    "libavcodec.so.59", "libavformat.so.59", "libavutil.so.57", "libswscale.so.6",
    "libgif.so.7", "libheif.so.1", "libopenjp2.so.7", "libopenvdb.so.10.0", "libraw_r.so.20",
    "libwebp.so.7", "libwebpdemux.so.2", "libOpenColorIO.so.2.1", "libtiff.so.6",
}
# What OpenImageIO calls of the replaced by stand-ins libraries before it writes a PNG or EXR (found by running refray on the stand-ins
# alone, tools/gpu_bundle.sh's check): C++ constructors and destructors (Itanium mangling C1/C2/C3, D0/D1/D2; its
# static initialisers construct DCMTK's DiRegister) and libtiff's handler setters. These stand-ins return instead of
# trapping; the objects stay zero and unused.
INERT = re.compile(r"(C[123]|D[012])E|^TIFFSet(Error|Warning)Handler$")
# Version queries: OpenImageIO asks every format library for its version when it lists its plug-ins (before it
# writes any file), so these stand-ins answer "" (an empty string, which also reads as a harmless number).
VERSION = re.compile(r"version", re.IGNORECASE)
# The C and C++ runtimes: every Linux machine has them (Ubuntu 24.04's are newer than Debian 12's).
SYSTEM = {"libc.so.6", "libm.so.6", "libdl.so.2", "libpthread.so.0", "librt.so.1", "ld-linux-x86-64.so.2",
          "libstdc++.so.6", "libgcc_s.so.1"}


def run(*args):
    return subprocess.run(args, check=True, capture_output=True, text=True).stdout


def library_paths():
    paths = {}
    for line in run("ldconfig", "-p").splitlines()[1:]:
        m = re.match(r"\s*(\S+) \(([^)]*)\) => (\S+)", line)
        if m and "x86-64" in m.group(2) and m.group(1) not in paths:
            paths[m.group(1)] = m.group(3)
    return paths


def needed(path):
    return re.findall(r"\(NEEDED\)\s+Shared library: \[([^\]]+)\]", run("readelf", "-d", "-W", path))


def dynamic_symbols(path):
    """(name, version, defined, type, size) of every dynamic symbol."""
    out = []
    for line in run("readelf", "--dyn-syms", "-W", path).splitlines():
        f = line.split()
        if len(f) < 8 or not f[0].endswith(":") or f[4] not in ("GLOBAL", "WEAK"):
            continue
        name, version = f[7], ""
        if "@" in name:
            name, _, version = name.partition("@")
            version = version.lstrip("@")
        out.append((name, version, f[6] != "UND", f[3], int(f[2], 0) if f[2].startswith("0x") else int(f[2])))
    return out


def main():
    binary, outdir = sys.argv[1], sys.argv[2]
    paths = library_paths()
    # Carried: the closure of the binary's NEEDED, without the runtimes and without what a stand-in replaces.
    carried, stand_ins_needed, todo = {}, set(), needed(binary)
    while todo:
        soname = todo.pop()
        if soname in SYSTEM or soname in carried:
            continue
        if soname in STAND_INS:
            stand_ins_needed.add(soname)
            continue
        if soname not in paths:
            sys.exit(f"gpu_bundle_libraries.py: {soname} is not installed here")
        carried[soname] = paths[soname]
        todo.extend(needed(paths[soname]))

    # What the carried libraries import, by (name, version).
    imports = set()
    for path in carried.values():
        imports.update((n, v) for n, v, defined, _, _ in dynamic_symbols(path) if not defined)

    os.makedirs(os.path.join(outdir, "stand-ins"), exist_ok=True)
    for soname in sorted(stand_ins_needed):
        real = paths[soname]
        functions, objects, nodes = [], [], {}
        for name, version, defined, kind, size in dynamic_symbols(real):
            if not defined or (name, version) not in imports and (name, "") not in imports:
                continue
            if kind == "FUNC" or kind == "IFUNC":
                functions.append(name)
            elif kind in ("OBJECT", "TLS"):
                objects.append((name, max(size, 8)))
            else:
                continue
            nodes.setdefault(version, []).append(name)
        base = os.path.join(outdir, "stand-ins", soname)
        with open(base + ".c", "w") as c:
            c.write("/* Generated by tools/gpu_bundle_libraries.py: a stand-in of %s for the GPU bundle. */\n" % soname)
            c.write("extern int dprintf(int, const char*, ...);\n")
            c.write("static void stand_in_called(const char* name) {\n"
                    "    dprintf(2, \"refray: %%s of the GPU bundle's stand-in %s was called; carry the real "
                    "library\\n\", name);\n    __builtin_trap();\n}\n" % soname)
            for name in functions:
                if VERSION.search(name):
                    c.write("const char* %s(void) { return \"\"; }\n" % name)  # listed by OIIO's plug-in catalogue
                elif INERT.search(name):
                    c.write("void %s(void) {}\n" % name)  # a constructor/destructor a static initialiser runs
                else:
                    c.write("void %s(void) { stand_in_called(\"%s\"); }\n" % (name, name))
            for name, size in objects:
                c.write("char %s[%d] __attribute__((aligned(16)));\n" % (name, size))
        with open(base + ".map", "w") as m:
            for version, names in sorted(nodes.items()):
                if version:
                    m.write("%s {\n  global:\n%s};\n" % (version, "".join("    %s;\n" % n for n in names)))
        args = ["cc", "-shared", "-fPIC", "-O0", "-w", "-o", base, base + ".c", "-Wl,-soname," + soname]
        if any(nodes):
            args.append("-Wl,--version-script=" + base + ".map")
        subprocess.run(args, check=True)
        os.remove(base + ".c")
        os.remove(base + ".map")
    with open(os.path.join(outdir, "carried.txt"), "w") as f:
        for soname, path in sorted(carried.items()):
            f.write("%s %s\n" % (soname, path))
    print("%d libraries carried, %d replaced by stand-ins" % (len(carried), len(stand_ins_needed)))


if __name__ == "__main__":
    main()
