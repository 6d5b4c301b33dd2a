import sys
import numpy as np
import checks as C
import generate as G

def my_openloop(P, u, dt, n, res, tight=1.0):
    mdl = G.build_model(P, res, dt)
    mdl.atol = [a * tight for a in mdl.atol]; mdl.rtol *= tight
    return C.replay_openloop(mdl, P, u, dt, n)

def run(d, tmax):
    m, tr, ex = C.load(d)
    P = C.truth_spec(m, tr)
    e = ex['fit']; dt = e['t'][1]; res = m['sensor']['resolution']
    n = min(len(e['t']), int(tmax / dt))
    a = my_openloop(P, e['u'], dt, n, res)
    b = my_openloop(P, e['u'], dt, n, res, 1e-3)
    c = C.ref_openloop(P, e['u'], dt, n)
    qm = e['q'][:n]
    print(d[-5:], tr['causes'] or 'clean', f'n={n} max|mine-tight|={np.max(np.abs(a-b))/res:.2e} res, '
          f'max|mine-solve_ivp|={np.max(np.abs(a-c))/res:.2e} res, max|tight-solve_ivp|={np.max(np.abs(b-c))/res:.2e} res; '
          f'stored-enc vs mine mism {np.sum(res*np.round(a/res)!=qm)}, vs solve_ivp {np.sum(res*np.round(c/res)!=qm)}')

if __name__ == '__main__':
    for d in sys.argv[2:]:
        run(d, float(sys.argv[1]))
