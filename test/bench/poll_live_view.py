#!/usr/bin/env python3
"""Asks a `featsense live --view` run for its changes about every second, as the live page
does (/live/status.json, then /live/mesh.bin?since=V where the version moved), until the run
ends; writes what it got as JSON: polls, bytes per poll, fetch times, the map's growth.
Usage: poll_live_view.py LIVE_LOG OUT.json (LIVE_LOG: the run's output, which names the URL)."""
import json
import re
import sys
import time
import urllib.request


def wait_for_url(log):
    for _ in range(600):
        try:
            match = re.search(r'map in the browser: (http://\S+/)', open(log).read())
        except FileNotFoundError:
            match = None
        if match:
            return match.group(1)
        time.sleep(0.1)
    sys.exit(f'{log}: no URL of a live view')


def get(url):
    start = time.monotonic()
    with urllib.request.urlopen(url, timeout=10) as response:
        body = response.read()
    return body, 1000 * (time.monotonic() - start)


def main():
    log, out = sys.argv[1], sys.argv[2]
    base = wait_for_url(log)
    polls, version, path_length, failures = [], 0, 0, 0
    while failures < 3:
        time.sleep(1.0)
        try:
            body, status_ms = get(f'{base}live/status.json?path_from={path_length}')
            status = json.loads(body)
            path_length = status['path_length']
            poll = {'t': time.monotonic(), 'status_ms': round(status_ms, 1),
                    'triangles': status['triangles'], 'chunks': status['chunks'],
                    'chunks_waiting': status['chunks_waiting'], 'meshing_ms': status['meshing_ms'],
                    'pose_latency_ms': status['pose_latency_ms']}
            if status['version'] != version:
                body, mesh_ms = get(f'{base}live/mesh.bin?since={version}')
                version = int.from_bytes(body[8:12], 'little')
                poll.update(mesh_bytes=len(body), mesh_ms=round(mesh_ms, 1),
                            changed_chunks=int.from_bytes(body[12:16], 'little'))
            polls.append(poll)
            failures = 0
            if status['finished']:
                break
        except OSError:
            failures += 1  # the run has ended (or is busy): a few tries, then done
    meshes = [p for p in polls if 'mesh_bytes' in p]
    def median(values):
        values = sorted(values)
        return values[len(values) // 2] if values else None
    summary = {
        'polls': len(polls), 'refreshes_fetched': len(meshes),
        'mesh_mb_total': round(sum(p['mesh_bytes'] for p in meshes) / 2**20, 1),
        'mesh_mb_max': round(max((p['mesh_bytes'] for p in meshes), default=0) / 2**20, 2),
        'changed_chunks_median': median([p['changed_chunks'] for p in meshes]),
        'mesh_fetch_ms_median': median([p['mesh_ms'] for p in meshes]),
        'meshing_ms_median': median([p['meshing_ms'] for p in polls if p['meshing_ms']]),
        'chunks_waiting_max': max((p['chunks_waiting'] for p in polls), default=0),
        'final_triangles': polls[-1]['triangles'] if polls else 0,
        'final_chunks': polls[-1]['chunks'] if polls else 0,
    }
    json.dump({'summary': summary, 'polls': polls}, open(out, 'w'), indent=1)
    print(json.dumps(summary))


main()
