# perobj.sh DRIFT REF TEST SCENE(sph|tex): per-object flip/luminance via drift diff --mask, plus whole image
# Issue 41 s6. Run from the repository root: bash THIS DRIFT REF.exr TEST.exr sph|tex (masks in /tmp/ggx6/masks_{sph,tex},
# from bench/cycles/gltf_object_masks.py)
D=$1; REF=$2; T=$3; S=$4
if [ $S = sph ]; then objs="Metal0 Metal1 Metal2 Metal3 Glass Floor"; else objs="Floor Wall"; fi
line=""
for o in $objs; do
  j=$($D diff $REF $T --mask /tmp/ggx6/masks_$S/mask_$o.exr --json)
  line="$line $(python3 -c "import json,sys; d=json.loads(sys.argv[1]); print('%s %.4f %.3f' % ('$o', d['flip'], d['luminance']))" "$j") |"
done
w=$($D diff $REF $T --json | python3 -c "import json,sys; print('%.4f' % json.load(sys.stdin)['flip'])")
echo "$(basename $T):$line whole $w"
