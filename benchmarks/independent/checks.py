#!/usr/bin/env python3
"""Checks for the generated data (python checks.py DATADIR [DATADIR ...])."""
import glob
import json
import math
import os
import sys

import numpy as np
from scipy import signal
from scipy.integrate import solve_ivp

import generate as G

HERE = os.path.dirname(os.path.abspath(__file__))


def load(d):
    m = json.load(open(os.path.join(d, 'model.json')))
    tr = json.load(open(os.path.join(d, 'truth.json')))
    ex = {k: dict(np.load(os.path.join(d, k + '.npz'))) for k in ('fit', 'val')}
    return m, tr, ex


def replay_u(q, qref, dt, c):
    e = q - qref
    I = dt * np.cumsum(e)
    de = np.concatenate([[0.0], np.diff(e)])
    tf = c['tau_f']
    D = signal.lfilter([1.0 / (tf + dt)], [1.0, -tf / (tf + dt)], de)
    u = -(c['kp'] * e + c['kd'] * D + c['ki'] * I)
    sat = np.zeros(len(u), bool)
    if 'saturation' in c:
        sat = np.abs(u) > c['saturation']
        u = np.clip(u, -c['saturation'], c['saturation'])
    return u, sat


def check_replay(dirs):
    worst = 0.0
    worst_el = 0.0
    nsat = 0
    ntot = 0
    nrec = 0
    for d in dirs:
        m, tr, ex = load(d)
        c = m['controller']
        res = m['sensor']['resolution']
        for k, e in ex.items():
            t, q, u, qr = e['t'], e['q'], e['u'], e['q_ref']
            assert t[0] == 0.0 and len(t) == len(q) == len(u) == len(qr)
            dt = t[1] - t[0]
            assert np.allclose(np.diff(t), dt, rtol=1e-9, atol=0)
            assert np.max(np.abs(q / res - np.round(q / res))) < 1e-6
            ur, sat = replay_u(q, qr, dt, c)
            ok = ~sat
            scale = np.max(np.abs(u))
            rel = np.max(np.abs(ur[ok] - u[ok])) / scale
            el = np.max(np.abs(ur[ok] - u[ok]) / (np.abs(u[ok]) + 1e-6 * scale))
            worst = max(worst, rel)
            worst_el = max(worst_el, el)
            nsat += int(sat.sum())
            ntot += len(u)
        nrec += 1
    print(f'replay: {nrec} records, max |du|/max|u| = {worst:.2e}, '
          f'max elementwise |du|/(|u|+1e-6 max|u|) = {worst_el:.2e}, '
          f'saturated samples {nsat}/{ntot}')
    return worst


# ------------------------------------------------------------------
def spec_from_model(m):
    nom = dict(m=m['plant']['mass'], cm=m['plant']['motor_constant'], Fc=m['friction']['Fc'],
               Fs=m['friction']['Fs'], vs=m['friction']['vs'], beta=int(m['friction']['beta']),
               b=m['friction']['b'])
    return G.nominal_spec(nom), nom


def truth_spec(m, tr):
    P, nom = spec_from_model(m)
    c = tr['causes'][0] if tr['causes'] else None
    p = tr['params']
    if c == 'offset':
        P['offset'] = p['offset']
    elif c == 'asymmetry':
        P['Fc_n'], P['Fs_n'], P['b_n'] = p['Fc_neg'], p['Fs_neg'], p['b_neg']
    elif c == 'cogging':
        P['cog'] = dict(A=p['A'], pitch=p['pitch'], phi=p['phi'])
    elif c == 'stribeck':
        P['Fs_p'] = P['Fs_n'] = p['Fs']
        P['vs'] = p['vs']
    elif c == 'viscous':
        P['b_p'] = P['b_n'] = p['b']
    elif c == 'mass':
        P['m'] = p['mass']
    elif c == 'delay':
        P['delay'] = p['delay']
    elif c == 'flexibility':
        P['kind'] = 'flex'
        P['flex'] = dict(m1=p['m1'], m2=p['m2'], k=p['k'], c=p['c'])
    elif c == 'reversal':
        P['kind'] = 'lugre'
        P['lugre'] = dict(sigma0=p['sigma0'], sigma1=p['sigma1'])
    elif c == 'dwell':
        P['dwell'] = dict(dFs_p=p['dFs'], dFs_n=p['dFs'], tau=p['tau'])
    return P


class RefPlant:
    """Independent plant integrator (scipy solve_ivp DOP853 / Radau with terminal events),
    same interface as the generator's models: pos(), vel(), mode, advance(t0, t1, F)."""

    def __init__(self, P):
        self.P = P
        self.kind = P['kind']
        self.flex = self.kind == 'flex'
        self.mode = 0 if self.kind != 'lugre' else None
        self.t_stick = -math.inf
        self.Fs_ep = P['Fs_p']
        self.nsteps = 0
        self.nevents = 0
        n = {'lugre': 3, 'flex': 4}.get(self.kind, 2)
        self.y = np.zeros(n)
        self.opts = dict(rtol=1e-12, atol=1e-16)

    def pos(self):
        return float(self.y[0])

    def vel(self):
        return float(self.y[1])

    def shape(self, v):
        return math.exp(-(abs(v) / self.P['vs']) ** self.P['beta'])

    def fcog(self, q):
        cog = self.P.get('cog')
        return cog['A'] * math.sin(2 * math.pi * q / cog['pitch'] + cog['phi']) if cog else 0.0

    def thr(self, t):
        P, dw = self.P, self.P.get('dwell')
        if dw:
            bonus = 1.0 if self.t_stick == -math.inf else 1 - math.exp(-(t - self.t_stick) / dw['tau'])
            return P['Fs_p'] + dw['dFs_p'] * bonus, P['Fs_n'] + dw['dFs_n'] * bonus
        return P['Fs_p'], P['Fs_n']

    def fric(self, v, s):
        P = self.P
        if s > 0:
            return P['Fc_p'] + (self.Fs_ep - P['Fc_p']) * self.shape(v) + P['b_p'] * v
        return -(P['Fc_n'] + (self.Fs_ep - P['Fc_n']) * self.shape(v)) + P['b_n'] * v

    def fapp(self, y, F):
        if self.flex:
            fl = self.P['flex']
            return F - fl['k'] * (y[0] - y[2]) - fl['c'] * (y[1] - y[3])
        return F - self.fcog(y[0])

    def advance(self, t, t_end, F):
        P = self.P
        if self.kind == 'lugre':
            s0, s1 = P['lugre']['sigma0'], P['lugre']['sigma1']
            Fc, Fs, b, m = P['Fc_p'], P['Fs_p'], P['b_p'], P['m']

            def f(t_, y):
                g = Fc + (Fs - Fc) * self.shape(y[1])
                zd = y[1] - s0 * abs(y[1]) * y[2] / g
                return [y[1], (F - s0 * y[2] - s1 * zd - b * y[1]) / m, zd]
            L = Fs / s0
            sol = solve_ivp(f, (t, t_end), self.y, method='Radau', rtol=1e-10,
                            atol=[1e-16, 1e-14, 1e-10 * L])
            self.y = sol.y[:, -1]
            return
        if self.flex:
            fl = P['flex']
            m1, m2, kk, cc = fl['m1'], fl['m2'], fl['k'], fl['c']
        y = self.y
        guard = 0
        while t_end - t > 1e-13:
            guard += 1
            if guard > 1000:
                raise RuntimeError('reference chattering')
            if self.mode == 0:
                fa = self.fapp(y, F)
                tp, tn = self.thr(t)
                if fa > tp:
                    self.mode, self.Fs_ep = 1, tp
                elif fa < -tn:
                    self.mode, self.Fs_ep = -1, tn
                elif not self.flex:
                    break
            s = self.mode
            if s != 0:
                def f(t_, y_, s=s):
                    if self.flex:
                        fs = kk * (y_[0] - y_[2]) + cc * (y_[1] - y_[3])
                        return [y_[1], (F - fs - self.fric(y_[1], s)) / m1, y_[3], fs / m2]
                    return [y_[1], (F - self.fcog(y_[0]) - self.fric(y_[1], s)) / P['m']]

                def ev(t_, y_, s=s):
                    return s * y_[1]
            else:  # flex stick: motor held, load moves
                def f(t_, y_):
                    return [0.0, 0.0, y_[3], (kk * (y_[0] - y_[2]) - cc * y_[3]) / m2]

                def ev(t_, y_):
                    fa = F - kk * (y_[0] - y_[2]) + cc * y_[3]
                    return min(P['Fs_p'] - fa, P['Fs_n'] + fa)
            ev.terminal = True
            ev.direction = -1
            sol = solve_ivp(f, (t, t_end), y, method='DOP853', events=ev, **self.opts)
            y = sol.y[:, -1].copy()
            t = sol.t[-1]
            if sol.status == 1:
                self.nevents += 1
                y = sol.y_events[0][0].copy()
                t = sol.t_events[0][0]
                fa = self.fapp(y, F)
                if s != 0:
                    y[1] = 0.0
                    fa = self.fapp(y, F)
                    if -P['Fs_n'] <= fa <= P['Fs_p']:
                        self.mode, self.t_stick = 0, t
                    elif fa > 0:
                        self.mode, self.Fs_ep = 1, P['Fs_p']
                    else:
                        self.mode, self.Fs_ep = -1, P['Fs_n']
                else:
                    self.mode = 1 if fa > 0 else -1
                    self.Fs_ep = P['Fs_p'] if self.mode > 0 else P['Fs_n']
        self.y = y


def ref_openloop(P, u, dt, nmax):
    """Open-loop replay of a stored u with the independent reference plant."""
    return replay_openloop(RefPlant(P), P, u, dt, nmax)


def replay_openloop(plant, P, u, dt, nmax):
    """Positions (nmax,) of ``plant`` (an object with pos() and advance(t0, t1, F)) driven
    open-loop by the stored u through the actuator delay P['delay'] (a fractional delay splits
    each sample interval in two)."""
    cm, off, delay = P['cm'], P['offset'], P['delay']
    nd = int(math.floor(delay / dt + 1e-12))
    r = delay - nd * dt
    if r < 1e-12:
        r = 0.0
    qs = np.zeros(nmax)
    for k in range(nmax):
        qs[k] = plant.pos()
        t, t1 = k * dt, (k + 1) * dt
        ua = u[k - nd - 1] if k - nd - 1 >= 0 else 0.0
        ub = u[k - nd] if k - nd >= 0 else 0.0
        if r > 0:
            plant.advance(t, t + r, cm * ua - off)
            plant.advance(t + r, t1, cm * ub - off)
        else:
            plant.advance(t, t1, cm * ub - off)
    return qs


def ref_closedloop(d, tmax):
    """Closed-loop re-simulation of a noise-free record's fit experiment with the
    independent plant in place of the generator's integrator; compare encoder outputs."""
    m, tr, ex = load(d)
    P = truth_spec(m, tr)
    e = ex['fit']
    dt = e['t'][1]
    n = min(len(e['t']), int(tmax / dt))
    orig = G.build_model
    G.build_model = lambda P_, res_, dt_, energy=False: RefPlant(P_)
    try:
        sim = G.simulate(P, dict(m['controller']), m['sensor']['resolution'], e['q_ref'][:n], dt)
    finally:
        G.build_model = orig
    mism = sim['q'] != e['q'][:n]
    first = int(np.argmax(mism)) if mism.any() else None
    res = m['sensor']['resolution']
    return n, int(mism.sum()), (first * dt if first is not None else None), \
        float(np.max(np.abs(sim['q'] - e['q'][:n])) / res), \
        float(np.max(np.abs(sim['u'] - e['u'][:n])) / np.max(np.abs(e['u'][:n])))


def check_openloop(d, nmax=None, tmax=3.0):
    m, tr, ex = load(d)
    if 'noise' in m['sensor'] or tr['actuator_noise']:
        print(f'{d}: has noise, skipped')
        return
    P = truth_spec(m, tr)
    e = ex['fit']
    dt = e['t'][1]
    n = min(len(e['t']), int(tmax / dt)) if nmax is None else nmax
    qs = ref_openloop(P, e['u'], dt, n)
    res = m['sensor']['resolution']
    qm = res * np.round(qs / res)
    diff = np.abs(qm - e['q'][:n]) / res
    # distance of the reference q to the nearest rounding boundary
    frac = np.abs(qs / res - np.floor(qs / res) - 0.5)
    bad = diff > 0.5
    print(f'{os.path.basename(d)} {tr["causes"] or ["clean"]}: open-loop solve_ivp replay of stored u, '
          f'{n} samples: encoder mismatch in {int(bad.sum())} samples '
          f'(max {diff.max():.0f} steps); min distance to rounding boundary among mismatches '
          f'{(frac[bad].max() if bad.any() else float("nan")):.2e} res; '
          f'q range {np.ptp(qs) * 1e3:.3g} mm')
    return bad.sum()


def check_stick(d):
    m, tr, ex = load(d)
    P, nom = spec_from_model(m)
    C = dict(m['controller'])
    e = ex['val']
    dt = e['t'][1]
    sim = G.simulate(P, C, m['sensor']['resolution'], e['q_ref'], dt, log=True, energy=True)
    md, v, q, fa, thr = sim['mode'], sim['v_true'], sim['q_true'], sim['fapp'], sim['thr']
    st = md == 0
    vmax_stick = np.max(np.abs(v[st])) if st.any() else float('nan')
    # q constant during each stick run
    dq = 0.0
    for k in range(1, len(q)):
        if st[k] and st[k - 1]:
            dq = max(dq, abs(q[k] - q[k - 1]))
    # force balance in stick: |F_app| <= Fs (F of last segment before t_k)
    over = np.max(np.maximum(fa[st] - thr[st, 0], -thr[st, 1] - fa[st])) if st.any() else 0
    model = sim['model']
    y = model.y
    ke = 0.5 * P['m'] * y[1] ** 2
    Win, Wfr = y[2], y[3]
    print(f'{os.path.basename(d)} stick check: {st.mean() * 100:.1f} % of samples in stick, '
          f'max |v| in stick = {vmax_stick:.1e}, max |dq| between stick samples = {dq:.1e}, '
          f'max (|F_app| - Fs) in stick = {over:.3g} N (<=0 ok), '
          f'{sim["nevents"]} events')
    print(f'   energy: W_in = {Win:.6g} J, W_fric = {Wfr:.6g} J, KE_end = {ke:.3g} J, '
          f'residual (W_in - W_fric - KE)/W_in = {(Win - Wfr - ke) / Win:.2e}; '
          f'W_fric >= 0 monotone: {bool(Wfr >= 0)}')
    return sim


def check_tolerance(d):
    """Re-simulate a record's fit experiment with 1000x tighter tolerances."""
    m, tr, ex = load(d)
    P = truth_spec(m, tr)
    C = dict(m['controller'])
    e = ex['fit']
    dt = e['t'][1]
    res = m['sensor']['resolution']
    a = G.simulate(P, C, res, e['q_ref'], dt, log=True)
    # tighten: monkeypatch builder
    orig = G.build_model

    def tight(P_, res_, dt_, energy=False):
        mdl = orig(P_, res_, dt_, energy)
        mdl.atol = [x * 1e-3 for x in mdl.atol]
        mdl.rtol = mdl.rtol * 1e-3
        return mdl
    G.build_model = tight
    try:
        b = G.simulate(P, C, res, e['q_ref'], dt, log=True)
    finally:
        G.build_model = orig
    dq = np.abs(a['q_true'] - b['q_true'])
    first = np.argmax(np.abs(a['q'] - b['q']) > 0) if np.any(a['q'] != b['q']) else None
    print(f'{os.path.basename(d)} {tr["causes"] or ["clean"]}: tol x1e-3: steps {a["nsteps"]} -> {b["nsteps"]}, '
          f'max |dq_true| = {dq.max() / res:.2e} res, encoder differs in '
          f'{int(np.sum(a["q"] != b["q"]))}/{len(dq)} samples, first at t={first * dt if first is not None else None}, '
          f'rms diff {G.rms(a["q"] - b["q"]) / res:.2e} res')


def plot(d, fn, title):
    import matplotlib
    matplotlib.use('Agg')
    import matplotlib.pyplot as plt
    m, tr, ex = load(d)
    fig, axs = plt.subplots(3, 2, figsize=(14, 9), sharex='col')
    for j, k in enumerate(('fit', 'val')):
        e = ex[k]
        axs[0, j].plot(e['t'], e['q_ref'] * 1e3, label='q_ref')
        axs[0, j].plot(e['t'], e['q'] * 1e3, '--', label='q')
        axs[0, j].set_ylabel('mm')
        axs[0, j].legend()
        axs[0, j].set_title(f'{k}')
        axs[1, j].plot(e['t'], (e['q'] - e['q_ref']) * 1e6)
        axs[1, j].set_ylabel('q - q_ref [um]')
        axs[2, j].plot(e['t'], e['u'])
        axs[2, j].set_ylabel('u [V]')
        axs[2, j].set_xlabel('t [s]')
    fig.suptitle(f'{title}: {os.path.basename(os.path.dirname(d))}/{os.path.basename(d)} '
                 f'{tr["causes"] or "clean"}')
    fig.tight_layout()
    fig.savefig(fn, dpi=80)
    plt.close(fig)


if __name__ == '__main__':
    for dd in sys.argv[1:]:
        dirs = sorted(glob.glob(os.path.join(dd, 'd0*')))
        check_replay(dirs)
