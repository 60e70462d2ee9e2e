#!/bin/bash
# The lab's A/B programs (issue 46, session 7): main's (554ca4b) glare convolution and post DOF compiled
# beside this tree's (renamed), linked with this tree's build/release/libdrift.a.
#   bash docs/lab/2026-12-07-issue-46-s7-passes-ab/build.sh /tmp/ab7
#   /tmp/ab7/glare_time 3; /tmp/ab7/post_dof_time 5
set -euo pipefail
out=$1; here=$(cd "$(dirname "$0")" && pwd); R=$(cd "$here/../../.." && pwd)
base=${BASE:-554ca4b} # main when this branch began
mkdir -p "$out"; cd "$out"
git -C "$R" show $base:src/glare/fft.c > old_fft.c
git -C "$R" show $base:src/glare/convolve.c > old_convolve.c
git -C "$R" show $base:src/glare/glare_internal.h > glare_internal.h # the old files' own header
git -C "$R" show $base:src/raster/post_dof.c > old_post_dof.c
FL="-O3 -DNDEBUG -std=gnu11 -ffp-contract=off -fno-math-errno -fno-trapping-math -I$R/include
    -I$R/build/release/generated/include -I$R/src -I/usr/include/kissfft"
REN="-Ddrift__glare_rfft_create=old_rfft_create -Ddrift__glare_rfft_destroy=old_rfft_destroy
     -Ddrift__glare_rfft_forward=old_rfft_forward -Ddrift__glare_rfft_inverse=old_rfft_inverse
     -Ddrift__glare_fft_create=old_fft_create -Ddrift__glare_fft_destroy=old_fft_destroy
     -Ddrift__glare_fft_run=old_fft_run -Ddrift__glare_fft_size=old_fft_size
     -Ddrift__glare_conv_release=old_conv_release -Ddrift__glare_convolve=old_convolve"
gcc $FL $REN -c old_fft.c -o old_fft.o
gcc $FL -Ddrift_post_dof=old_post_dof -Ddrift_coc_lens_make=old_lens_make \
    -Ddrift_coc_radius_pixels=old_coc_radius -c old_post_dof.c -o old_post_dof.o
gcc $FL $REN -c old_convolve.c -o old_convolve.o
LIB="$R/build/release/libdrift.a -lkissfft-float -lm -lpthread"
gcc $FL "$here/glare_time.c" old_fft.o old_convolve.o $LIB -o glare_time
gcc $FL "$here/post_dof_time.c" old_post_dof.o $LIB -o post_dof_time
