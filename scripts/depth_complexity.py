#!/usr/bin/env python3
"""Depth complexity of the real scenes of ../shared/scenes under --cull none and --cull auto.

usage: depth_complexity.py [MFR] [SCENES_DIR]
    MFR: the mfr binary (default build/mfr); SCENES_DIR: default ../shared/scenes

Per scene and cull mode: `mfr info SCENE --width 512 --height 512 --orbit 13 --cull MODE --json`
(13 perspective views on a circle, the CPU engine's count pass), then the fragments summed over
the views, the largest per-pixel count of any view, and the mean over covered pixels (summed
fragments / summed covered pixels). Prints a Markdown table (docs/GLTF.md).
"""
import json
import subprocess
import sys

SCENES = [
    ("IridescentDishWithOlives", "khronos/IridescentDishWithOlives/glTF/IridescentDishWithOlives.gltf"),
    ("StainedGlassLamp", "khronos/StainedGlassLamp/glTF-JPG-PNG/StainedGlassLamp.gltf"),
    ("GlassVaseFlowers", "khronos/GlassVaseFlowers/glTF-Binary/GlassVaseFlowers.glb"),
    ("TransmissionTest", "khronos/TransmissionTest/glTF-Binary/TransmissionTest.glb"),
    ("AlphaBlendModeTest", "khronos/AlphaBlendModeTest/glTF-Binary/AlphaBlendModeTest.glb"),
    ("Stanford bunny", "stanford/bunny/bun_zipper.ply"),
    ("Stanford dragon", "stanford/dragon/dragon_100k.ply"),
]


def main():
    mfr = sys.argv[1] if len(sys.argv) > 1 else "build/mfr"
    root = sys.argv[2] if len(sys.argv) > 2 else "../shared/scenes"
    print("| scene | --cull | fragments (13 views) | max | mean |")
    print("|---|---|---|---|---|")
    for name, relative in SCENES:
        for cull in ("none", "auto"):
            run = subprocess.run([mfr, "info", f"{root}/{relative}", "--width", "512", "--height",
                                  "512", "--orbit", "13", "--cull", cull, "--json", "-q"],
                                 capture_output=True, text=True)
            if run.returncode != 0:
                print(f"| {name} | {cull} | error: {run.stderr.strip()} | | |")
                continue
            views = json.loads(run.stdout)["views"]
            fragments = sum(v["fragments"] for v in views)
            covered = sum(v["covered_pixels"] for v in views)
            largest = max(v["max_depth_complexity"] for v in views)
            print(f"| {name} | {cull} | {fragments:,} | {largest} | {fragments / covered:.2f} |")
    return 0


if __name__ == "__main__":
    sys.exit(main())
