"""Refinement of a selected explanation: the continuous hyper-parameters of its members (a
cogging pitch, a Stribeck velocity, a bristle stiffness and damping, a resonance, a delay) by
Gauss-Newton in log scale from the search's grid values, and the coefficients' and hyper-
parameters' covariance (the delta method's).

The coefficients come from the same estimate as the search's (:mod:`hunting.diagnose.force`):
generalized least squares, or instrumental variables for a set with an instrumented member. A
step is shortened as a whole to at most ``max_step`` in log scale (clipped per key, it left the
Gauss-Newton direction and climbed along curved valleys such as sigma0 against the bristle
damping) and halved up to ``HALVINGS`` times while it does not fit better."""
from __future__ import annotations

import numpy as np

from .causes import CAUSES, hyper_keys
from .force import Explanation, Library, unphysical_members
from .kinematics import Kinematics
from .stats import gls, instrumented

HALVINGS = 3          # a refinement step that does not fit better is halved at most this many times


def refine(lib: Library, ex: Explanation, *, iterations: int = 4, max_step: float = 0.25):
    """Gauss-Newton refinement of the continuous hyper-parameters (``HYPER_KEYS`` of a cause:
    a pitch, a Stribeck velocity, a bristle stiffness, a resonance) of an explanation's members
    in log scale, from their grid values; returns (explanation, theta, cov, hyper sigmas {name:
    {key: sigma}}). theta and cov come from the GLS fit (:func:`stats.gls`), or the instrumented
    one (:func:`stats.instrumented`) when a member is instrumented, with the hyper-parameters'
    sensitivity columns appended (their covariance is the delta method's).

    A member whose extension fixes its coefficients (``EXTENSION_COEFFICIENTS``: the reversal's
    LuGre build-up has scale 1) has its hyper-parameters refined a second time with those
    coefficients held, its regressor a known force change: the hyper-parameters reported are then
    the extension's own. Its free coefficients are re-estimated at them (the reversal's scale is
    the check that the build-up is LuGre's). With the scale free, a build-up 0.33 times LuGre's
    at 2.7 times the damping fitted a blind record as well as the true sigma0 did (sigma0 60 %
    low); held at 1, sigma0 came out within 1 %."""
    idx, run, noise = lib.Sf.idx, lib.Sf.run, lib.noise
    bounds = _hyper_bounds(lib, ex.members)
    fixed = {n: np.asarray(CAUSES[n].EXTENSION_COEFFICIENTS, float) for n, _ in ex.members
             if getattr(CAUSES[n], "EXTENSION_COEFFICIENTS", None) is not None}
    y = lib.y_thin

    def design(mem, held):
        """(X, Z, s): the free members' regressors, their instruments (X's own columns where a
        member is not instrumented; None when none is) and the known force changes (shifts, and
        the held members' regressors at their fixed coefficients) on the thinned fitting data."""
        X, Z, s = [], [], np.zeros(idx.size)
        for name, j in mem:
            v = lib.variants[name][j]
            s = s + v.sf[idx]
            if name in held:
                s = s + v.Xf[idx] @ fixed[name]
                continue
            X.append(v.Xf[idx])
            Z.append((v.Zf if v.Zf is not None else v.Xf)[idx])
        if not X:
            return np.zeros((idx.size, 0)), None, s
        free = [(n, j) for n, j in mem if n not in held]
        return np.column_stack(X), (np.column_stack(Z) if lib.instrumented(free) else None), s

    def sensitivities(mem, theta, Z, held):
        """(G, GZ): d(force change)/d(log h) per hyper key (:func:`_sensitivity`) on the fitting
        record and, for instrumented members, on its instrument trajectory (GZ None when Z is)."""
        cols, zcols, k = [], [], 0
        for name, j in mem:
            v = lib.variants[name][j]
            kk = v.Xf.shape[1]
            th = fixed[name] if name in held else theta[k:k + kk]
            for key in hyper_keys(name, v.hyper):
                col = _sensitivity(lib, name, v.hyper, key, th, lib.kf)
                cols.append(col)
                zcols.append(_sensitivity(lib, name, v.hyper, key, th, lib.kfr) if v.Zf is not None else col)
            k += 0 if name in held else kk
        if not cols:
            return np.zeros((idx.size, 0)), (None if Z is None else np.zeros((idx.size, 0)))
        return np.column_stack(cols), (None if Z is None else np.column_stack(zcols))

    def estimate(X, Z, yy):
        if not X.shape[1]:
            yw, _ = noise.whiten(yy, run)
            return np.zeros(0), np.zeros((0, 0)), float(yw @ yw), int(yw.size)
        return gls(X, yy, run, noise) if Z is None else instrumented(X, Z, yy, run, noise)

    def physical(mem, theta, held) -> bool:
        full, k = [], 0
        for name, j in mem:
            kk = lib.variants[name][j].Xf.shape[1]
            full.append(fixed[name] if name in held else theta[k:k + kk])
            k += 0 if name in held else kk
        theta = np.concatenate(full) if full else np.zeros(0)
        return not unphysical_members(lib, mem, theta) and not (len(mem) > 1 and lib.cancelling_variants(mem, theta))

    def fitted(mem, held):
        X, Z, s = design(mem, held)
        theta, cov, rss, _ = estimate(X, Z, y - s)
        return dict(members=list(mem), X=X, Z=Z, s=s, theta=theta, cov=cov, rss=rss)

    def starts(cur, held, names):
        """The best fitting physical of the members' own starting variants (``refine_starts``:
        the reversal's bristle damping) for the members ``names``."""
        for m, (name, j) in enumerate(list(cur["members"])):
            fn = getattr(CAUSES[name], "refine_starts", None)
            if name not in names or fn is None:
                continue
            for h in fn(lib.variants[name][j].hyper):
                lib.variants[name].append(lib.variant(name, h))
                trial = cur["members"][:m] + [(name, len(lib.variants[name]) - 1)] + cur["members"][m + 1:]
                t = fitted(trial, held)
                if t["rss"] < cur["rss"] and physical(trial, t["theta"], held):
                    cur = t
        return cur

    def descend(cur, held, steps):
        keys = [k for n, j in cur["members"] for k in hyper_keys(n, lib.variants[n][j].hyper)]
        for _ in range(steps if keys else 0):
            G, GZ = sensitivities(cur["members"], cur["theta"], cur["Z"], held)
            X, Z = cur["X"], cur["Z"]
            th_aug = estimate(np.column_stack([X, G]), None if Z is None else np.column_stack([Z, GZ]), y - cur["s"])[0]
            step = th_aug[X.shape[1]:]
            # shortened as a whole, not clipped per key: a clipped step leaves the Gauss-Newton
            # direction and, along a curved valley (sigma0 against zeta), climbs
            step = step * min(1.0, max_step / max(float(np.max(np.abs(step))), 1e-300))
            if np.all(np.abs(step) < 1e-3):
                break
            for _ in range(HALVINGS + 1):        # the step, halved while it does not fit better
                trial = moved(cur["members"], step)
                t = fitted(trial, held)
                if t["rss"] < cur["rss"] and physical(trial, t["theta"], held):
                    break
                step = step / 2
            else:
                break
            cur = t
        return cur

    def moved(mem, step):
        """The members with their hyper-parameters moved by ``step`` (log scale, within bounds)."""
        trial, i = [], 0
        for name, j in mem:
            v = lib.variants[name][j]
            h = dict(v.hyper)
            for key in hyper_keys(name, v.hyper):
                lo, hi = bounds[name][key]
                h[key] = float(np.clip(v.hyper[key] * np.exp(step[i]), lo, hi))
                i += 1
            if h != v.hyper:
                lib.variants[name].append(lib.variant(name, h))
                j = len(lib.variants[name]) - 1
            trial.append((name, j))
        return trial

    def hyper_cov(cur, held):
        """The covariance of [free coefficients, log hyper-parameters] with the sensitivities."""
        G, GZ = sensitivities(cur["members"], cur["theta"], cur["Z"], held)
        X, Z = cur["X"], cur["Z"]
        return estimate(np.column_stack([X, G]), None if Z is None else np.column_stack([Z, GZ]), y - cur["s"])[1]

    cur = descend(starts(fitted(ex.members, ()), (), {n for n, _ in ex.members}), (), iterations)
    has_keys = any(hyper_keys(n, lib.variants[n][j].hyper) for n, j in cur["members"])
    k = cur["X"].shape[1]
    # the linear parameters' covariance with the hyper-parameters free, at the free optimum (a
    # held member's coefficients are judged there: is the data's build-up identified at all?)
    cov_aug = hyper_cov(cur, ()) if has_keys else None
    cov = cov_aug[:k, :k] if has_keys else cur["cov"]
    held_fit = None
    if fixed:
        held = tuple(fixed)
        held_fit = descend(starts(fitted(cur["members"], held), held, set(fixed)), held, 2 * iterations)
        cur = fitted(held_fit["members"], ())      # the free coefficients at the extension's hyper-parameters
    if not physical(cur["members"], cur["theta"], ()):
        return _unrefined(fitted(ex.members, ()), ex, physical)
    members, X, theta = cur["members"], cur["X"], cur["theta"]
    sig = {}
    if has_keys:
        hc = (hyper_cov(held_fit, tuple(fixed)), held_fit["X"].shape[1]) if held_fit else (cov_aug, k)
        i = 0
        for name, j in members:
            for key in hyper_keys(name, lib.variants[name][j].hyper):
                h = lib.variants[name][j].hyper[key]
                sig.setdefault(name, {})[key] = float(h * np.sqrt(max(hc[0][hc[1] + i, hc[1] + i], 0.0)))
                i += 1
    return Explanation(tuple(members), theta, ex.bic, cur["rss"], list(range(X.shape[1]))), theta, cov, sig


def _unrefined(start: dict, ex: Explanation, physical):
    """refine's answer where the refined fit is not physical: the explanation at its grid
    variants, re-estimated (``start``, refine's own fit) where that is physical, else with the
    search's coefficients and no covariance. Two members that one record cannot tell apart (an
    offset and a Coulomb level on a record that moves one way) make the design all but singular:
    the re-estimate split their common force into +-2.2e8 N (reporting38 d0443, a Stribeck level
    of -2.2e8 N reported beside an offset of -2.2e8 N), which the grid fit had split into +-0.22 N."""
    if physical(start["members"], start["theta"], ()):
        return (Explanation(tuple(start["members"]), start["theta"], ex.bic, start["rss"],
                            list(range(start["X"].shape[1]))), start["theta"], start["cov"], {})
    return ex, ex.theta, None, {}


def _hyper_bounds(lib: Library, members) -> dict:
    """{name: {key: (lo, hi)}}: the refinement's range of each member's hyper-parameters, the
    cause's own (``hyper_bounds``) or the searched variants' range, 3 % wider."""
    bounds = {}
    for name, _ in members:
        mod = CAUSES[name]
        b = getattr(mod, "hyper_bounds", None)
        b = b(lib.kf, lib.model) if b else {}
        for key in getattr(mod, "HYPER_KEYS", ()):
            if key not in b:
                vals = [v.hyper[key] for v in lib.variants[name]]
                b[key] = (min(vals) / 1.03, max(vals) * 1.03)
        bounds[name] = b
    return bounds


def _sensitivity(lib: Library, name: str, hyper: dict, key: str, theta: np.ndarray, kin: Kinematics) -> np.ndarray:
    """d(force change)/d(log hyper[key]) (m,) of one cause at coefficients theta on the thinned
    fitting samples of the kinematics ``kin`` (the record's or its instrument trajectory's):
    central differences at +-1 %."""
    mod = CAUSES[name]
    sh = getattr(mod, "shift", None)
    out = []
    for f in (1.01, 1 / 1.01):
        h = dict(hyper, **{key: hyper[key] * f})
        x = mod.design(kin, lib.model, h)[lib.Sf.idx] @ theta
        out.append(x + (sh(kin, lib.model, h)[lib.Sf.idx] if sh else 0.0))
    return (out[0] - out[1]) / (2 * np.log(1.01))


def members_parameters(lib, ex, cov=None) -> list:
    """Per member of an explanation: (name, hyper, theta block, final parameters, sigma,
    increments, the model after it); the extensions are applied in member order, each cause's
    parameters read from the model it extends (the final values: no two members change the same
    field)."""
    out = []
    cur = lib.model
    k = 0
    for name, j in ex.members:
        mod = CAUSES[name]
        v = lib.variants[name][j]
        kk = v.Xf.shape[1]
        th = ex.theta[k:k + kk]
        pars = mod.parameters(th, v.hyper, cur)
        base = mod.parameters(np.zeros(kk), v.hyper, cur)
        inc = {key: float(pars[key] - base[key]) for key in pars if key not in v.hyper}
        sig = {}
        for key in pars:
            if key in v.hyper or cov is None:
                sig[key] = None
                continue
            grad = np.zeros(kk)
            for i in range(kk):
                h = 1e-6 * max(1.0, abs(th[i]))
                tp = th.copy()
                tp[i] += h
                grad[i] = (mod.parameters(tp, v.hyper, cur)[key] - pars[key]) / h
            blk = cov[k:k + kk, k:k + kk]
            sig[key] = float(np.sqrt(max(grad @ blk @ grad, 0.0)))
        cur = mod.extend(cur, th, v.hyper)
        out.append((name, v.hyper, th.copy(), pars, sig, inc, cur))
        k += kk
    return out


def member_sigma(name: str, parameters: dict, sigma: dict, hyper_sigma: dict) -> dict:
    """A member's standard uncertainties complete: ``sigma`` (its coefficients', from
    :func:`members_parameters`) with its refined hyper-parameters' (``hyper_sigma``, refine's
    {name: {key: sigma}}) and those of parameters computed from them (the cause's
    ``derived_sigma``)."""
    sig = dict(sigma, **hyper_sigma.get(name, {}))
    derived = getattr(CAUSES[name], "derived_sigma", None)
    if derived is not None:             # parameters computed from refined hyper-parameters
        sig.update(derived(parameters, sig))
    return sig
