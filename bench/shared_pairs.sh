# Sourced by bench/auto.sh and bench/viewpoint_light.sh (after common.sh, with `work` set to a
# folder of their own): the night-like variants and the parts of the shared traversals that
# their pairs use, the ground truth of the parts, and `truth KIND`, the ground-truth keys of a
# pair (aligned, rtab, kitti, sussex or none), and `figures JSON`, the figures of a run's --json.
data="$datasets"
night="$work/night"; mkdir -p "$night"
gp="$data/gardens_point"; nl="$data/nordland_trimmed"
make() { night_like "$night" "$@"; }  # make NAME SOURCE ARGS
make gp_right_night "$gp/day_right" --seed 1
make gp_right_night_strong "$gp/day_right" --strong --seed 2
make gp_right_night_extreme "$gp/day_right" --strong --seed 6 --zoom 0.15 --shift 0.08 --rotation 5 --noise 1.5
make nord_summer_night "$nl/summer" --seed 3
make nord_winter_night "$nl/winter" --seed 4
make nord_summer_night_strong "$nl/summer" --strong --from-left --seed 5
make nord_winter_night_extreme "$nl/winter" --strong --from-left --seed 7 --zoom 0.1 --shift 0.06 --rotation 4 --noise 1.3

# Folders of parts of a traversal (links), and the ground truth of the parts.
part() { link_part "$work/parts/$1" "${@:2}"; }  # part NAME FOLDER FIRST COUNT
part nord_s0 "$nl/summer" 1 300; part nord_w0 "$nl/winter" 1 300
part nord_w600 "$nl/winter" 601 300; part nord_s600 "$nl/summer" 601 300
part nord_s1200 "$nl/summer" 1201 300; part nord_w1200 "$nl/winter" 1201 300
part nord_summer_a "$nl/summer" 1 600; part nord_winter_b "$nl/winter" 1101 600
part nord_winter_c "$nl/winter" 1101 200
part rtab_lap1 "$data/rtabmap_samples/images" 1 40; part rtab_lap2 "$data/rtabmap_samples/images" 41 44
part kitti_ref "$data/kitti00_first1700/image_0" 41 221; part kitti_qry "$data/kitti00_first1700/image_0" 1501 200
# RTAB-Map laps: images 41-84 revisit 1-40 (1-based ids in the pairs file).
awk '!/^#/ && $1 >= 41 && $2 <= 40 {print $1 - 41 "," $2 - 1}' \
  "$data/rtabmap_samples/ground_truth_pairs.txt" > "$work/rtab_pairs.csv"
sed -n '41,261p' "$data/kitti00_first1700/poses/00_first1700.txt" > "$work/kitti_ref_poses.txt"
# Sussex panoramas: the re-run's 96 tracked frames against the training route (true places within
# 30 cm of the tracked positions), as bench/sussex_panoramas.sh.
sx="$data/sussex_panoramas"
[ -d "$work/sussex_rerun" ] || "$root/build/bench/shift_panoramas" "$sx/test_infomax_binary" "$work/sussex_rerun" 0 96 > /dev/null
awk 'NR > 1 && $5 == 0 {print $3 "," $4}' "$sx/gt_positions_training.txt" > "$work/sussex_train.csv"
awk 'NR > 1 && $5 == 0 {print $3 "," $4}' "$sx/gt_positions_test_infomax_binary.txt" | head -96 > "$work/sussex_rerun.csv"
sed -n '1501,1700p' "$data/kitti00_first1700/poses/00_first1700.txt" > "$work/kitti_qry_poses.txt"
truth() {  # the ground-truth keys of a pair
  case "$1" in
    aligned) echo "--set Ground_truth_type=aligned --set Tolerance=2" ;;
    rtab) echo "--set Ground_truth_type=pairs --set Ground_truth=$work/rtab_pairs.csv --set Ground_truth_base=0 --set Tolerance=1" ;;
    kitti) echo "--set Ground_truth_type=kitti --set Ground_truth=$work/kitti_ref_poses.txt --set Ground_truth_2=$work/kitti_qry_poses.txt --set Ground_truth_axes=xz --set Ground_truth_radius=5 --set Ground_truth_heading=45 --set Tolerance=3" ;;
    sussex) echo "--set Ground_truth_type=positions --set Ground_truth=$work/sussex_train.csv --set Ground_truth_2=$work/sussex_rerun.csv --set Ground_truth_radius=30 --set Tolerance=0 --set Camera_type=2 --set Panoramas=4 --set Panorama_matching=0" ;;
    none) echo "" ;;
  esac
}
# figures JSON: "R@1|AUC|R@100P|accepted|precision" of a run's --json ("-" without ground truth),
# then "|reliable|chosen|consistency" of its auto mode when it has one.
figures() {
  python3 - "$1" <<'PY'
import json, sys
j = json.load(open(sys.argv[1]))
e = j["evaluation"]
a = j.get("auto")
acc = j["accepted"]
if e:
    q = e["runs"][0]["per_query"]
    op = q.get("accepted", {})
    print("%.3f|%.3f|%.3f|%d|%.3f" % (q["recall_at_1"], q["auc"], q["recall_at_100p"],
                                      op.get("matches", 0), op.get("precision", 1)), end="")
else:
    print("-|-|-|%d|-" % (acc["queries"] if acc else 0), end="")
if a:
    c = [x for x in a["candidates"] if x["rank"] == 1][0]
    print("|%s|%s|%.3f" % ("yes" if a["reliable"] else "**no**", a["chosen"], c["consistency"]))
else:
    print()
PY
}
