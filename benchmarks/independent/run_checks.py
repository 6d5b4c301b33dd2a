#!/usr/bin/env python3
"""Run all checks on generated sets: python run_checks.py SETDIR [SETDIR...]"""
import glob, json, os, sys, time
from collections import defaultdict
import numpy as np
import checks as C
import generate as G
from ol_compare import my_openloop

HERE = os.path.dirname(os.path.abspath(__file__))


def recs(sd):
    out = []
    for d in sorted(glob.glob(os.path.join(sd, 'd0*'))):
        m = json.load(open(os.path.join(d, 'model.json')))
        t = json.load(open(os.path.join(d, 'truth.json')))
        out.append((d, m, t))
    return out


for sd in sys.argv[1:]:
    print('=' * 30, sd)
    R = recs(sd)
    C.check_replay([r[0] for r in R])
    s = json.load(open(os.path.join(sd, 'summary.json')))
    print(f'generation time {s["seconds"]:.0f} s')
    # per-cause cut ranges
    g = defaultdict(list)
    att = defaultdict(list)
    for d, m, t in R:
        c = t['causes'][0] if t['causes'] else 'clean'
        g[c].append(t['val_error_cut'])
        att[c].append(t['attempts'])
    for c in G.CAUSES:
        v = np.array(g[c], float)
        print(f'  {c:12s} val cut min {v.min():.2f} median {np.median(v):.2f} max {v.max():.2f}  attempts {att[c]}')
    sat = [max(t['saturation_fraction'].values()) for d, m, t in R if 'saturation' in m['controller']]
    print(f'  saturation declared in {len(sat)} records, max saturated fraction {max(sat) if sat else 0:.2e}')
    nn = sum(1 for d, m, t in R if 'noise' in m['sensor'])
    na = sum(1 for d, m, t in R if t['actuator_noise'])
    uni = sum(1 for d, m, t in R if 'unidirectional' in t['notes'])
    print(f'  sensor noise declared in {nn}, actuator noise in {na}, a unidirectional programme in {uni} records')
    # stick / energy on clean records with rests (noise-free re-simulation of the nominal)
    done = 0
    for d, m, t in R:
        if t['clean'] and 'p2p' in t['notes'].split('val programme:')[1].split(',')[0]:
            C.check_stick(d)
            done += 1
            if done >= 2:
                break
    # independent integrator (scipy solve_ivp DOP853/Radau + terminal events) on noise-free
    # records, one per cause: (a) open-loop replay of the stored u, (b) closed loop with the
    # same PID code
    seen = set()
    for d, m, t in R:
        c = t['causes'][0] if t['causes'] else 'clean'
        if c in seen or 'noise' in m['sensor'] or t['actuator_noise']:
            continue
        seen.add(c)
        P = C.truth_spec(m, t)
        e = dict(np.load(os.path.join(d, 'fit.npz')))
        dt = e['t'][1]; res = m['sensor']['resolution']
        tm = 1.0 if c == 'reversal' else 2.0
        n = min(len(e['t']), int(tm / dt))
        t0 = time.time()
        a = my_openloop(P, e['u'], dt, n, res)
        ref = C.ref_openloop(P, e['u'], dt, n)
        dif = np.abs(a - ref) / res
        k3 = int(0.3 / dt)
        big = np.argmax(dif > 1e-3) * dt if np.any(dif > 1e-3) else None
        ncl, nmis, first, maxd, maxu = C.ref_closedloop(d, tm)
        print(f'  indep. {os.path.basename(d)} {c:12s} open-loop: max diff first 0.3 s {dif[:k3].max():.1e} res, '
              f'diff >1e-3 res from t={big}; closed-loop {ncl} samples: encoder mismatches {nmis}, '
              f'first at t={first}, max {maxd:.0f} steps ({time.time() - t0:.1f}s)', flush=True)
    # closed-loop tolerance sensitivity
    seen = set()
    for d, m, t in R:
        c = t['causes'][0] if t['causes'] else 'clean'
        if c in seen or c not in ('clean', 'reversal', 'flexibility', 'dwell', 'stribeck'):
            continue
        seen.add(c)
        C.check_tolerance(d)

# plots of three records of the first set
R = recs(sys.argv[1])
pick = {}
for d, m, t in R:
    c = t['causes'][0] if t['causes'] else 'clean'
    if c in ('clean', 'dwell', 'reversal') and c not in pick:
        if c == 'clean' and 'p2p' not in t['notes']:
            continue
        pick[c] = d
for c, d in pick.items():
    fn = os.path.join(HERE, f'plot_{c}.png')
    C.plot(d, fn, c)
    print('plot', fn, d)
