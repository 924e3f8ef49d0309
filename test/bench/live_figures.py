#!/usr/bin/env python3
"""The figures of live runs (test/bench/live_replay.sh) as one JSON object per run: latencies,
what the real-time policy gave up, the poses' and the mesh's errors against the simulation's
truth, memory. Usage: live_figures.py WORK NAME... (a NAME may also be an offline `map` output
folder made with --reference-trajectory and --reference)."""
import json
import os
import sys


def timing(t):
    return {k: round(t[k], 1) for k in ('median_ms', 'p95_ms', 'max_ms') if k in t}


def figures(work, name):
    folder = os.path.join(work, name)
    r = json.load(open(os.path.join(folder, 'report.json')))
    t = r['timings']
    ev = r.get('eval', {})
    ape = ev.get('traj', {}).get('ape', {})
    mesh = ev.get('mesh', {})
    aligned = mesh.get('aligned', {}).get('accuracy', {})
    out = {
        'run': name,
        'scans_read': r['frames_read'],
        'scans_with_pose': sum(1 for l in open(os.path.join(folder, 'trajectory.tum')) if l.strip() and not l.startswith('#')),
        'scans_integrated': r['frames'],
        'real_time': r.get('real_time'),
        'warnings': r.get('warnings'),
        'latency': {k: timing(v) for k, v in t.get('latency', {}).items()},
        'locate': timing(t['locate']),
        'integrate': timing(t['integrate']),
        # live --view: the mapping thread's copies per refresh (the meshing is apart).
        'preview': dict(timing(t['preview']), count=t['preview'].get('count', 0))
                   if t.get('preview', {}).get('count') else None,
        'ate_m': {k: round(ape[k], 4) for k in ('mean', 'rmse', 'max') if k in ape},
        'mesh_aligned_m': {k: round(aligned[k], 4) for k in ('mean_abs', 'median', 'p95')
                           if k in aligned},
        'backend': r.get('backend'),
        'wall_s': round(r['wall_s'], 1),
        'peak_rss_mb': round(r.get('peak_rss_mb', 0)),
    }
    replay = os.path.join(work, name + '.replay.json')
    rss = os.path.join(work, name + '.rss.txt')
    if os.path.exists(replay):
        rp = json.load(open(replay))
        out['replay'] = {k: rp[k] for k in ('rate', 'sent', 'dropped', 'failed', 'seconds')}
        if os.path.exists(rss):
            # While the packets came: the largest resident size in each half of the sending
            # (flat memory: about the same), and over the whole run (meshing at the end).
            samples = [(float(w[0]), int(w[1])) for w in (l.split() for l in open(rss))
                       if len(w) == 2]
            if samples:
                start = samples[0][0]
                sending = [kb for t, kb in samples if t - start <= rp['seconds']]
                half = max(1, len(sending) // 2)
                out['rss_mb_sending_halves'] = [round(max(sending[:half]) / 1024),
                                                round(max(sending[half:] or sending) / 1024)]
                out['rss_mb_max'] = round(max(kb for _, kb in samples) / 1024)
    return out


for run in sys.argv[2:]:
    print(json.dumps(figures(sys.argv[1], run)))
