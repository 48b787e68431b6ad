"""Tables of the robustness sweep (results/robustness/sweep.sh): summary.csv and summary.md.

usage: summarize.py RUNS_DIR OUT_DIR   (RUNS_DIR holds <dataset>_s<stride>_<config>/metrics.json)
"""
import csv
import glob
import json
import os
import statistics
import sys

CONFIGS = [("default", "svd_ncc_gabor, prediction: motion_prior, platform: auto (the library "
            "default; the simulated robot runs as a ground vehicle)"),
           ("free", "svd_ncc_gabor, prediction: motion_prior, platform: free (6-DoF; the default "
            "before 2026-12-03)"),
           ("paper", "svd_ncc_gabor, prediction: none, platform: free (the paper as published)"),
           ("lucas_kanade", "lucas_kanade, prediction: motion_prior, platform: auto"),
           ("ncc_mutual", "ncc_mutual, prediction: motion_prior, platform: auto"),
           ("few_point", "svd_ncc_gabor, platform: free, tracking.few_point_motion: true"),
           ("few_point_ground", "svd_ncc_gabor, platform: free, tracking.few_point_motion: true, "
            "ground_vehicle: true"),
           ("ground", "svd_ncc_gabor, platform: free, tracking.ground_vehicle: true"),
           ("few_point_ground_rig", "svd_ncc_gabor, platform: free, tracking.few_point_motion: "
            "true, ground_vehicle: true, few_point.axle_behind_camera_m: 0.15 (the rig's "
            "camera.forward_m)"),
           ("few_point_ground_rig_planar", "svd_ncc_gabor, platform: free, "
            "tracking.few_point_motion: true, ground_vehicle: true, vehicle_planar_ba: true, "
            "few_point.axle_behind_camera_m: 0.15"),
           ("few_point_ground_rig_planar_floor", "svd_ncc_gabor, platform: free, "
            "tracking.few_point_motion: true, ground_vehicle: true, vehicle_planar_ba: true, "
            "vehicle_flat_floor: true, few_point.axle_behind_camera_m: 0.15 (what platform "
            "ground_vehicle switches on)")]
KEYS = ["end_pose_error_m", "end_pose_error_pct", "ate_rmse_m", "lost_frames",
        "reinitialisations", "vo_ms_median"]


def main(runs_dir, out_dir):
    rows = []
    for path in sorted(glob.glob(os.path.join(runs_dir, "*", "metrics.json"))):
        name = os.path.basename(os.path.dirname(path))
        dataset, rest = name.split("_s", 1)
        stride, config = rest.split("_", 1)
        m = json.load(open(path))
        rows.append(dict(dataset=dataset, stride=int(stride), config=config,
                         **{k: m.get(k, "") for k in KEYS}))
    rows.sort(key=lambda r: ([c for c, _ in CONFIGS].index(r["config"]), r["dataset"] != "vga",
                             r["dataset"], r["stride"]))
    with open(os.path.join(out_dir, "summary.csv"), "w", newline="") as f:
        w = csv.DictWriter(f, fieldnames=["dataset", "stride", "config"] + KEYS)
        w.writeheader()
        w.writerows(rows)

    def get(d, k, c):
        return next((r for r in rows if r["dataset"] == d and r["stride"] == k and r["config"] == c), None)

    seeds = ["seed%d" % s for s in range(1, 11)]
    md = ["# Robustness sweep (issue #9)", "",
          "l_hallway (16 m, 485 frames), only `textures.seed` changed; frame strides 1, 2, 3, 5 "
          "(the in-place turn moves the image ~10 px per frame at stride 1, ~49 px at stride 5), "
          "plus a pitched and a 640x480 camera and the low-texture `plain_corridor` scene. "
          "Made by `results/robustness/sweep.sh` (same frames as `suites/robustness.yaml`; "
          "rendered in the KITTI layout, without an IMU, so every configuration here runs "
          "without the gyro, as `suites/robustness.yaml` with `imu.gyro_prior: false`; the "
          "default with the gyro: results/gyro_prior/vehicle_sweep.md). "
          "Cells: end-pose error in % of the path / frames without a measured motion.", ""]
    for c, title in CONFIGS:
        if not any(r["config"] == c for r in rows):
            continue
        md += ["## %s" % title, "",
               "| stride | " + " | ".join(s.replace("seed", "seed ") for s in seeds) +
               " | max (m) | median (m) | lost, all seeds |",
               "| --- |" + " --- |" * (len(seeds) + 3)]
        for k in (1, 2, 3, 5):
            cells, errs, lost = [], [], 0
            for s in seeds:
                r = get(s, k, c)
                if r is None:
                    cells.append("—")
                    continue
                cells.append("%.2f / %d" % (r["end_pose_error_pct"], r["lost_frames"]))
                errs.append(r["end_pose_error_m"])
                lost += r["lost_frames"]
            md.append("| %d | %s | %s | %s | %d |" % (
                k, " | ".join(cells), "%.3f" % max(errs) if errs else "—",
                "%.3f" % statistics.median(errs) if errs else "—", lost))
        extra = [("seed 7, stride 8", get("seed7", 8, c)), ("camera.pitch_deg 10", get("pitch10", 1, c)),
                 ("640x480 camera", get("vga", 1, c))] + [
                     ("plain_corridor (12 m), stride %d" % k, get("corridor", k, c)) for k in (1, 2, 3, 5)]
        md += ["", "| other | end-pose error | ATE | lost / re-initialised | VO ms/frame |",
               "| --- | --- | --- | --- | --- |"]
        for label, r in extra:
            if r:
                md.append("| %s | %.3f m (%.2f %%) | %.3f m | %d / %d | %.2f |" % (
                    label, r["end_pose_error_m"], r["end_pose_error_pct"], r["ate_rmse_m"],
                    r["lost_frames"], r["reinitialisations"], r["vo_ms_median"]))
        md.append("")
    md.append("VO ms/frame: median per frame of one run, two runs in parallel on a 2-core machine, "
              "as loaded as it was while the sweep ran (the runs of a re-made section may have "
              "shared it with other work): a rough cost, not a speed measurement "
              "(results/speed has the pinned ones).")
    open(os.path.join(out_dir, "summary.md"), "w").write("\n".join(md) + "\n")


if __name__ == "__main__":
    main(sys.argv[1], sys.argv[2])
