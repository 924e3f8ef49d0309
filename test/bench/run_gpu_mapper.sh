#!/usr/bin/env bash
# On the GPU machine, from the repository root, with .device/bundle.tar.xz carried along (packed
# as test/bench/pack_gpu_bundle.sh packs it, with featsense, tsdf_test_cuda_integrator,
# storage_test_shifting_map and mapping_test_map_pipeline): the CUDA parity tests, the
# pipeline's tests, and the demo through the Mapper on both backends (the same map expected bit
# for bit).
set -uo pipefail
tar xJf .device/bundle.tar.xz -C /tmp
export LD_LIBRARY_PATH=/tmp/bundle/lib
bin=/tmp/bundle/bin
out=${OUT:-/tmp/out}
mkdir -p "$out"
nvidia-smi --query-gpu=name,driver_version --format=csv,noheader
lscpu | grep "Model name"
"$bin/tsdf_test_cuda_integrator" 2>&1 | grep -E "parity|differ|OK \]|PASSED|FAILED|SKIPPED" | tail -30
"$bin/storage_test_shifting_map" 2>&1 | tail -3
"$bin/mapping_test_map_pipeline" 2>&1 | tail -3
for backend in cuda cpu; do
  /usr/bin/time -f "demo gt-poses $backend %e s %M KB" "$bin/featsense" demo --gt-poses --backend "$backend" -o /tmp/demo_gt_$backend --quiet
  md5sum /tmp/demo_gt_$backend/mesh.ply
  python3 -c "import json,sys; r=json.load(open('/tmp/demo_gt_$backend/report.json')); print('$backend', r['backend'], r['frames'], 'scans', round(r['scans_per_s'],1), 'scans/s', 'mesh mean', r['eval']['mesh']['accuracy']['mean_abs'])"
done
cmp /tmp/demo_gt_cuda/mesh.ply /tmp/demo_gt_cpu/mesh.ply && echo "CUDA and CPU demo meshes identical"
/usr/bin/time -f "demo odometry cuda %e s %M KB" "$bin/featsense" demo --backend cuda -o /tmp/demo_odo --quiet
python3 -c "import json; r=json.load(open('/tmp/demo_odo/report.json')); print('odometry cuda', r['backend'], r['frames'], 'ATE', r['eval']['traj']['ape']['rmse'], 'mesh mean', r['eval']['mesh']['accuracy']['mean_abs'], r['loops']['second_pass'])"
cp /tmp/demo_gt_cuda/report.json "$out/demo_gt_cuda_report.json"
cp /tmp/demo_odo/report.json "$out/demo_odo_cuda_report.json"
