# perobj.sh REF TEST: per-object FLIP/luminance (drift diff --mask), s6 masks
D=${DRIFT:-build/release/bin/drift}; REF=$1; T=$2
line=""
for o in Metal0 Metal1 Metal2 Metal3 Glass Floor; do
  j=$($D diff $REF $T --mask /tmp/ggx6/masks_sph/mask_$o.exr --json)
  line="$line $(python3 -c "import json,sys; d=json.loads(sys.argv[1]); print('%s %.4f %.3f' % ('$o', d['flip'], d['luminance']))" "$j") |"
done
echo "$(basename $T) vs $(basename $REF):$line"
