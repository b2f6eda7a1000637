#!/usr/bin/env python3
"""Issue 19, the 1e-7 target on the 2000-disk biaxial problem: an active-set polish
of NLGS's solution by linear programs (docs/PERFORMANCE.md, "An active-set polish by
linear programs"). Each contact gets a class (open, frictionless, stick, slip +/-)
from NLGS's impulses, then from the Alart-Curnier projection of the last iterate;
for given classes the frictional contact problem is linear (u = W r + q, u_n = 0 and
r in the cone for closed contacts, u_t = 0 when sticking, r_t = +-mu r_n and
+-u_t <= 0 when slipping, r = 0 and u_n >= 0 when open): a feasible point is an exact
solution. Solved with elastic (L1-penalised) class constraints by Clarabel.

Needs numpy, scipy and clarabel (`python3 -m venv v && v/bin/pip install numpy scipy
clarabel`). Usage, with the problem and NLGS's solution:
    nscdd export-fc base.toml --steps 200 --out bx200.json.gz
    nscdd solve-fc bx200.json.gz --tol 1e-4 --check-every 10 --max-sweeps 100000 > r1e4.json
    v/bin/python scripts/fc_polish_study.py bx200.json.gz r1e4.json [iterations]
"""
import json, gzip, sys, time
import numpy as np, scipy.sparse as sp, clarabel

P = json.load(gzip.open(sys.argv[1]))
n = P['W']['n']; nc = P['nc']
W = sp.coo_matrix((P['W']['vals'], (P['W']['rows'], P['W']['cols'])), shape=(n, n)).tocsr()
q = np.array(P['q']); mu = np.array(P['mu'])
def resid(r):
    u = W @ r + q
    R = r.reshape(-1, 2); U = u.reshape(-1, 2)
    z = R - np.c_[U[:, 0] + mu * np.abs(U[:, 1]), U[:, 1]]
    zn, zt = z[:, 0], z[:, 1]
    p = z.copy()
    inside = np.abs(zt) <= mu * zn
    polar = mu * np.abs(zt) <= -zn
    edge = ~inside & ~polar
    e = np.c_[np.ones(nc), mu * np.sign(zt)] / np.sqrt(1 + mu**2)[:, None]
    d = (z * e).sum(1)
    p[edge] = d[edge, None] * e[edge]
    p[polar] = 0
    return np.linalg.norm((R - p).ravel()) / np.linalg.norm(q)

def classify(r0):
    u0 = W @ r0 + q; R = r0.reshape(-1, 2); U = u0.reshape(-1, 2)
    rn, rt = R[:, 0], R[:, 1]
    cls = np.empty(nc, dtype=object)
    for a in range(nc):
        if rn[a] <= 0: cls[a] = 'O'
        elif mu[a] == 0: cls[a] = 'F'
        elif abs(rt[a]) >= mu[a] * rn[a] * (1 - 1e-9): cls[a] = 'S+' if rt[a] > 0 else 'S-'
        else: cls[a] = 'K'
    return cls

Wd = W.diagonal()

def active(r):
    """Classes from the projection z = r - rho (u + Phi(u)), rho = 1/W_nn (AC active sets)."""
    u = W @ r + q; R = r.reshape(-1, 2); U = u.reshape(-1, 2)
    rho = 1.0 / Wd[0::2]
    zn = R[:, 0] - rho * (U[:, 0] + mu * np.abs(U[:, 1])); zt = R[:, 1] - rho * U[:, 1]
    cls = np.empty(nc, dtype=object)
    for a in range(nc):
        if mu[a] == 0:
            cls[a] = 'F' if zn[a] > 0 else 'O'
        elif abs(zt[a]) <= mu[a] * zn[a]: cls[a] = 'K'
        elif mu[a] * abs(zt[a]) <= -zn[a]: cls[a] = 'O'
        else: cls[a] = 'S+' if zt[a] > 0 else 'S-'
    return cls

def solve(cls, r0, rs, us):
    rows = {'eq': [], 'in': []}; b = {'eq': [], 'in': []}; pen = []  # pen: (kind, row, weight)
    def add(kind, entries, rhs, soft=None):
        k = len(b[kind]); rows[kind].append(entries); b[kind].append(rhs)
        if soft is not None: pen.append((kind, k, soft))
    R = lambda a, i: 2 * a + i
    Uv = lambda a, i: n + 2 * a + i
    wu, wr = 1.0 / us, 1.0 / rs
    for a in range(nc):
        c = cls[a]; m = mu[a]
        if c == 'O':
            add('eq', [(R(a, 0), 1)], 0); add('eq', [(R(a, 1), 1)], 0); add('in', [(Uv(a, 0), -1)], 0, wu)
        else:
            add('eq', [(Uv(a, 0), 1)], 0, wu); add('in', [(R(a, 0), -1)], 0, wr)
            if c == 'F': add('eq', [(R(a, 1), 1)], 0)
            elif c == 'K':
                add('eq', [(Uv(a, 1), 1)], 0, wu)
                add('in', [(R(a, 1), 1), (R(a, 0), -m)], 0, wr); add('in', [(R(a, 1), -1), (R(a, 0), -m)], 0, wr)
            else:
                s = 1.0 if c == 'S+' else -1.0
                add('eq', [(R(a, 1), 1), (R(a, 0), -s * m)], 0); add('in', [(Uv(a, 1), s)], 0, wu)
    # slack variables: eq soft rows get p - m, in soft rows get -p
    nslack = sum(2 if k == 'eq' else 1 for k, _, _ in pen)
    nx = 2 * n + nslack
    def mat(kind):
        rr, cc, vv = [], [], []
        for i, ent in enumerate(rows[kind]):
            for c_, v in ent: rr.append(i); cc.append(c_); vv.append(v)
        return rr, cc, vv
    er, ec, ev = mat('eq'); ir, ic, iv = mat('in')
    cost = np.zeros(nx); col = 2 * n
    for kind, k, w in pen:
        if kind == 'eq':
            er += [k, k]; ec += [col, col + 1]; ev += [-1.0, 1.0]; cost[col] = cost[col + 1] = w; col += 2
        else:
            ir.append(k); ic.append(col); iv.append(-1.0); cost[col] = w; col += 1
    neq, nin = len(b['eq']), len(b['in'])
    A1 = sp.hstack([-W, sp.identity(n), sp.csr_matrix((n, nslack))])
    Aeq = sp.coo_matrix((ev, (er, ec)), shape=(neq, nx))
    Ain = sp.coo_matrix((iv, (ir, ic)), shape=(nin, nx))
    Aslk = sp.hstack([sp.csr_matrix((nslack, 2 * n)), -sp.identity(nslack)])
    A = sp.vstack([A1, Aeq, Ain, Aslk]).tocsc()
    bb = np.concatenate([q, b['eq'], b['in'], np.zeros(nslack)])
    Pm = sp.block_diag([sp.identity(n) * 1e-6 / rs**2, sp.csc_matrix((n + nslack, n + nslack))]).tocsc()
    cvec = cost.copy(); cvec[:n] += -1e-6 * r0 / rs**2
    st = clarabel.DefaultSettings(); st.verbose = False
    st.tol_gap_abs = st.tol_gap_rel = st.tol_feas = 1e-12; st.max_iter = 300
    cones = [clarabel.ZeroConeT(n + neq), clarabel.NonnegativeConeT(nin + nslack)]
    t = time.time()
    sol = clarabel.DefaultSolver(sp.triu(Pm).tocsc(), cvec, A, bb, cones, st).solve()
    x = np.array(sol.x)
    return x[:n], x[2 * n:] @ cost[2 * n:], str(sol.status), time.time() - t


if __name__ == '__main__':
    d = json.load(open(sys.argv[2]))
    r = np.array(d['r'])
    print('NLGS: residual', resid(r), 'sweeps', d['sweeps'], 'seconds', d['solve_seconds'])
    rs = np.abs(r).max(); us = np.abs(q).max()
    cls = classify(r)
    print({k: int((cls == k).sum()) for k in ['O', 'F', 'K', 'S+', 'S-']})
    t0 = time.time()
    for it in range(int(sys.argv[3]) if len(sys.argv) > 3 else 8):
        rn, obj, status, secs = solve(cls, r, rs, us)
        new = active(rn)
        changed = int((new != cls).sum())
        print(it, status, 'penalty', obj, 'residual', resid(rn), 'classes changed', changed, 'seconds', round(secs, 1), flush=True)
        r = rn
        if resid(r) < 1e-7 or changed == 0:
            break
        cls = new
    u = W @ r + q; U = u.reshape(-1, 2); closed = active(r) != 'O'
    un = U[closed, 0] / us
    print('total seconds', round(time.time() - t0, 1), '; closed contacts with u_n/max|q| > 1e-6:', int((un > 1e-6).sum()), ', < -1e-6:', int((un < -1e-6).sum()))
