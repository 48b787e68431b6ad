# The rendered L-hallway at a camera size, for results/speed/measure.sh and
# results/speed/viso2/measure.sh (sourced; needs ROOT, NEW and WORK):
#   variant NAME WIDTH HEIGHT FOVY_DEG BASELINE_M  ->  $WORK/ds_NAME (KITTI layout), once
variant() {
  sed -e "s|^name: l_hallway|name: $1|" -e "s|^scene: hallway_l.xml|scene: $ROOT/scenes/hallway_l.xml|" \
      -e "s|^  width: 320|  width: $2|;s|^  height: 240|  height: $3|" \
      -e "s|^  fovy_deg: 55 |  fovy_deg: $4 |;s|^  baseline_m: 0.09|  baseline_m: $5|" \
      "$ROOT/scenes/l_hallway.yaml" > "$WORK/$1.yaml"
  [ -d "$WORK/ds_$1" ] || { echo "rendering $1 ($2x$3)"; "$NEW" render "$WORK/$1.yaml" --out "$WORK/ds_$1" -q > /dev/null; }
}
