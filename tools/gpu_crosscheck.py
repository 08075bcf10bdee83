#!/usr/bin/env python3
"""The planning and bookkeeping half of tools/gpu_crosscheck.sh (standard library only: it runs on the GPU machine).

  gpu_crosscheck.py plan ROOT SIZE          what to render: one tab-separated line per render
                                            (what, name, scene, camera, time, size, precision, aov, output,
                                            extra refray arguments or "-")
  gpu_crosscheck.py settings ROOT           every golden's setting, a line each: name, scene, camera, time
                                            (tools/lavapipe_speed.sh and tools/pgo_train.sh render them)
  gpu_crosscheck.py metadata FILE.exr       the refray:* attributes of an EXR's header, as JSON
  gpu_crosscheck.py provenance DIR          writes DIR/provenance.json from DIR/plan.tsv, DIR/commands.txt,
                                            DIR/speed.tsv and the renders' headers
"""
import datetime
import glob
import json
import os
import struct
import subprocess
import sys

AOVS = ["record", "instance", "geometry", "primitive", "hitgroup"]
# The path tracer's statistical goldens are re-rendered on the GPU with seeds the golden was not made from.
STATS_FIRST_SEED = 100
SPEED_SIZE = "1280x720"


def aovs_of(root, scene):
    """The index maps of a scene: a compute scene ("pipeline": {"compute": ...}) traces its primary rays with RayQuery,
    which reads no shader record, so it has no record or hit-group map (docs/vulkan-backend.md, "AOVs")."""
    if scene == "builtin":
        return AOVS
    desc = json.load(open(os.path.join(root, scene)))
    if desc.get("pipeline", {}).get("compute"):
        return [a for a in AOVS if a not in ("record", "hitgroup")]
    return AOVS


def settings(root):
    for g in json.load(open(os.path.join(root, "tests/golden/goldens.json")))["goldens"]:
        print(g["name"], g["scene"], g["camera"], g["time"])


def plan(root, size):
    goldens = json.load(open(os.path.join(root, "tests/golden/goldens.json")))["goldens"]
    rows = []
    for g in goldens:
        setting = [g["scene"], g["camera"], g["time"], "%dx%d" % (g["width"], g["height"]), g["precision"]]
        rows.append(["image", g["name"]] + setting + ["-", "images/%s.exr" % g["name"], "-"])
        for aov in aovs_of(root, g["scene"]):
            rows.append(["map", g["name"]] + setting[:3] + [size, "float", aov, "maps/%s.%s.exr" % (g["name"], aov), "-"])
        rows.append(["speed", g["name"]] + setting[:3] + [SPEED_SIZE, g["precision"], "-", "-", "-"])
    # Path-traced scenes: a statistics image (--batches) at the statistical golden's settings, other seeds.
    manifest = json.load(open(os.path.join(root, "tests/golden/goldens.json")))
    for g in manifest.get("statistical", []):
        extra = "--spp %d --batches %d --seed %d" % (g["spp"], g["batches"], STATS_FIRST_SEED)
        rows.append(["stats", g["name"], g["scene"], g["camera"], "-", "%dx%d" % (g["width"], g["height"]), "float",
                     "-", "images/%s.stats.exr" % g["name"], extra])
    # The lessons that render: their own camera, the scene's default time.
    for path in sorted(glob.glob(os.path.join(root, "scenes/lessons/*.json"))):
        lesson = json.load(open(path))
        render = lesson.get("expect", {}).get("render")
        if render is None or render.get("diagnostic", "") != "":
            continue
        name = lesson["name"]
        scene = os.path.relpath(path, root)
        for aov in aovs_of(root, scene):
            rows.append(["map", name, scene, render.get("camera", "-"), "-", size, "float", aov,
                         "maps/%s.%s.exr" % (name, aov), "-"])
    for r in rows:
        print("\t".join(str(x) for x in r))


def exr_attributes(path):
    """The string attributes of a scanline EXR's header (refray writes its provenance there)."""
    out = {}
    with open(path, "rb") as f:
        data = f.read(1 << 20)
    assert struct.unpack("<I", data[:4])[0] == 20000630, path + " is no OpenEXR file"
    pos = 8
    while data[pos] != 0:
        end = data.index(b"\0", pos)
        name = data[pos:end].decode()
        tend = data.index(b"\0", end + 1)
        kind = data[end + 1:tend].decode()
        (size,) = struct.unpack("<i", data[tend + 1:tend + 5])
        value = data[tend + 5:tend + 5 + size]
        if kind == "string":
            out[name] = value.decode(errors="replace")
        pos = tend + 5 + size
    return {k[len("refray:"):]: v for k, v in out.items() if k.startswith("refray:")}


def provenance(directory):
    renders = []
    for line in open(os.path.join(directory, "plan.tsv")):
        fields = line.rstrip("\n").split("\t")
        what, name, scene, camera, time, size, precision, aov, output = fields[:9]
        extra = fields[9] if len(fields) > 9 else "-"
        if what == "speed":
            continue
        entry = {"what": what, "name": name, "scene": scene, "camera": camera, "time": time, "size": size,
                 "precision": precision, "file": output}
        if extra != "-":
            words = extra.split()
            for key in ("spp", "batches", "seed"):
                if "--" + key in words:
                    entry[key] = int(words[words.index("--" + key) + 1])
        if aov != "-":
            entry["aov"] = aov
        path = os.path.join(directory, output)
        entry["rendered"] = os.path.exists(path)
        if entry["rendered"]:
            meta = exr_attributes(path)
            entry["renderSeconds"] = meta.get("render_seconds")
        renders.append(entry)
    first = next((r for r in renders if r["rendered"]), None)
    meta = exr_attributes(os.path.join(directory, first["file"])) if first else {}
    speed = []
    speed_path = os.path.join(directory, "speed.tsv")
    if os.path.exists(speed_path):
        for line in open(speed_path):
            name, run, size, render_seconds, wall_seconds = line.rstrip("\n").split("\t")
            speed.append({"name": name, "run": int(run), "size": size, "renderSeconds": float(render_seconds),
                          "wallSeconds": float(wall_seconds)})
    smi = ""
    try:
        smi = subprocess.run(["nvidia-smi", "--query-gpu=name,driver_version", "--format=csv,noheader"],
                             capture_output=True, text=True, timeout=30).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        pass
    doc = {
        "format": "refray-gpu-renders/1",
        "comment": "Renders made on a GPU by tools/gpu_crosscheck.sh (refray render --device vulkan); "
                   "imported with tools/gpu_crosscheck.sh --import. Not refray's CPU renders.",
        "gpu": meta.get("gpu", ""),
        "gpuDriver": meta.get("gpu_driver", ""),
        "vulkanAPI": meta.get("vulkan_api", ""),
        "nvidiaSmi": smi,
        "date": datetime.datetime.now(datetime.timezone.utc).strftime("%Y-%m-%dT%H:%M:%SZ"),
        "refrayVersion": meta.get("refray_version", ""),
        "refrayCommit": meta.get("refray_commit", ""),
        "commands": [c for c in open(os.path.join(directory, "commands.txt")).read().splitlines() if c],
        "renders": renders,
        "speed": speed,
    }
    with open(os.path.join(directory, "provenance.json"), "w") as f:
        json.dump(doc, f, indent=1)
        f.write("\n")


if __name__ == "__main__":
    if len(sys.argv) == 4 and sys.argv[1] == "plan":
        plan(sys.argv[2], sys.argv[3])
    elif len(sys.argv) == 3 and sys.argv[1] == "settings":
        settings(sys.argv[2])
    elif len(sys.argv) == 3 and sys.argv[1] == "metadata":
        print(json.dumps(exr_attributes(sys.argv[2]), indent=1))
    elif len(sys.argv) == 3 and sys.argv[1] == "provenance":
        provenance(sys.argv[2])
    else:
        sys.exit(__doc__)
