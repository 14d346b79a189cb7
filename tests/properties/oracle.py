"""An independent numpy oracle for the rigidity counts of flexure's system types.

Nothing here is taken from flexure's C++ code: the constraint equations are the ones of the
paper's appendix B (approximating-continuous-motions.tex), the trivial motions are the symmetry
groups listed in SPEC.md (Euclidean for frameworks, body-hinge and packings; similarities for
angular frameworks; equi-affine maps for volume hypergraphs), applied to the points.

A `Model` holds one system: its type, vertices (n, d), the constraint index lists and the pinned
vertices. It gives the scaled residual (dimensionless: squared lengths / s^2, cosines, volumes /
s^d, with s the start's extent), the Jacobian in the free coordinates, the trivial-motion
generators, the counts (rank by SVD at a clear gap) and a small predictor-corrector tracker.
"""

import itertools

import numpy as np

# Rank decision on the row-normalized Jacobian: singular values above KEEP * sigma_max count,
# those below DROP * sigma_max are zero; anything in between makes the case "unclear".
KEEP = 1e-6
DROP = 1e-10
BIG = 200  # above this many free coordinates the tracker factors Gram matrices instead (faster)


def euclid_generators(P):
    """Infinitesimal Euclidean motions at P (n, d): rows are velocity fields (n*d)."""
    n, d = P.shape
    gens = []
    for k in range(d):
        v = np.zeros((n, d))
        v[:, k] = 1.0
        gens.append(v.ravel())
    c = P.mean(axis=0)
    Q = P - c
    for a, b in itertools.combinations(range(d), 2):
        v = np.zeros((n, d))
        v[:, a] = -Q[:, b]
        v[:, b] = Q[:, a]
        gens.append(v.ravel())
    return np.array(gens)


def similarity_generators(P):
    c = P.mean(axis=0)
    return np.vstack([euclid_generators(P), (P - c).ravel()[None, :]])


def equiaffine_generators(P):
    """Translations and x -> L x with trace(L) = 0."""
    n, d = P.shape
    c = P.mean(axis=0)
    Q = P - c
    gens = []
    for k in range(d):
        v = np.zeros((n, d))
        v[:, k] = 1.0
        gens.append(v.ravel())
    for a in range(d):
        for b in range(d):
            if a != b:
                v = np.zeros((n, d))
                v[:, a] = Q[:, b]  # E_ab
                gens.append(v.ravel())
    for a in range(d - 1):
        v = np.zeros((n, d))
        v[:, a] = Q[:, a]
        v[:, d - 1] = -Q[:, d - 1]  # E_aa - E_dd
        gens.append(v.ravel())
    return np.array(gens)


def _orth(A, rel=1e-9):
    """Orthonormal basis of the column space of A."""
    if A.size == 0:
        return np.zeros((A.shape[0], 0))
    U, s, _ = np.linalg.svd(A, full_matrices=False)
    if s.size == 0 or s[0] == 0:
        return np.zeros((A.shape[0], 0))
    return U[:, s > rel * s[0]]


def _null(A, rel=1e-9):
    """Orthonormal basis of the null space of A (columns)."""
    if A.shape[0] == 0:
        return np.eye(A.shape[1])
    _, s, Vt = np.linalg.svd(A)
    r = int(np.sum(s > rel * (s[0] if s.size else 1.0)))
    return Vt[r:].T


class Model:
    """kind: framework | body_hinge | sphere_packing | angular_framework | volume_hypergraph."""

    def __init__(self, kind, P, pinned=(), edges=None, angles=None, simplices=None, bodies=None):
        self.kind = kind
        self.P0 = np.array(P, dtype=float)
        self.n, self.d = self.P0.shape
        self.pinned = sorted(set(int(i) for i in pinned))
        ext = np.ptp(self.P0, axis=0).max()
        self.s = float(ext) if ext > 0 else 1.0
        if kind in ("framework", "sphere_packing"):
            self.E = np.array(edges, dtype=int).reshape(-1, 2)
        elif kind == "body_hinge":
            # each body rigid: a frame of affinely independent body vertices keeps its bar
            # lengths (the paper's K_n, restricted to the frame), every other vertex of the body
            # stays the same affine combination of the frame (3 linear equations). For bodies of
            # at most 4 vertices in general position this is exactly the paper's K_n.
            es, held = set(), []
            for b in bodies:
                b = [int(x) for x in b]
                frame = self._frame(b)
                for i, j in itertools.combinations(sorted(frame), 2):
                    es.add((i, j))
                F = self.P0[frame]
                for v in b:
                    if v in frame:
                        continue
                    # p_v = sum lam_f p_f, sum lam_f = 1
                    A = np.vstack([F.T, np.ones(len(frame))])
                    lam = np.linalg.lstsq(A, np.r_[self.P0[v], 1.0], rcond=None)[0]
                    held.append((v, list(frame), lam))
            self.E = np.array(sorted(es), dtype=int).reshape(-1, 2)
            self.held = held
        elif kind == "angular_framework":
            self.A = np.array(angles, dtype=int).reshape(-1, 3)
        elif kind == "volume_hypergraph":
            self.S = np.array(simplices, dtype=int).reshape(-1, self.d + 1)
        else:
            raise ValueError(kind)
        pinset = set(self.pinned)
        self.free_vertices = [i for i in range(self.n) if i not in pinset]
        self.free = np.array([i * self.d + k for i in self.free_vertices for k in range(self.d)], dtype=int)
        self.pincols = np.array([i * self.d + k for i in self.pinned for k in range(self.d)], dtype=int)
        # Equations that involve a free vertex (those among pinned vertices only are dropped).
        idx = self._index_lists()
        self.eq_keep = np.array([any(int(i) not in pinset for i in row) for row in idx], dtype=bool)
        self.targets = self._raw(self.P0)

    def _frame(self, body):
        """Affinely independent vertices of the body, greedily (at most d + 1)."""
        frame = [body[0]]
        for v in body[1:]:
            if len(frame) == self.d + 1:
                break
            Q = self.P0[frame + [v]] - self.P0[frame[0]]
            sv = np.linalg.svd(Q, compute_uv=False)
            scale = max(np.linalg.norm(Q, axis=1).max(), 1e-300)
            if sv.size and sv[len(frame) - 1] > 1e-6 * scale:
                frame.append(v)
        return frame

    # -- constraints
    def _index_lists(self):
        if self.kind == "body_hinge":
            return [list(e) for e in self.E] + [[v, *f] for v, f, _ in self.held for _k in range(self.d)]
        if self.kind in ("framework", "sphere_packing"):
            return self.E
        if self.kind == "angular_framework":
            return self.A
        return self.S

    def _raw(self, P):
        if self.kind == "body_hinge":
            D = P[self.E[:, 0]] - P[self.E[:, 1]]
            out = [np.sum(D * D, axis=1) / self.s ** 2]
            for v, f, lam in self.held:
                out.append((P[v] - lam @ P[f]) / self.s)
            return np.concatenate(out)
        if self.kind in ("framework", "sphere_packing"):
            D = P[self.E[:, 0]] - P[self.E[:, 1]]
            return np.sum(D * D, axis=1) / self.s ** 2
        if self.kind == "angular_framework":
            a = P[self.A[:, 0]] - P[self.A[:, 1]]
            b = P[self.A[:, 2]] - P[self.A[:, 1]]
            return np.sum(a * b, axis=1) / (np.linalg.norm(a, axis=1) * np.linalg.norm(b, axis=1))
        # signed volumes det [p; 1] (up to the constant factor d!)
        Pm = P[self.S]  # (m, d+1, d)
        M = Pm[:, 1:, :] - Pm[:, :1, :]
        return np.linalg.det(M) / self.s ** self.d

    def residual(self, x):
        """Scaled residual at the free coordinates x."""
        return (self._raw(self.config(x)) - self.targets)[self.eq_keep]

    def config(self, x):
        P = self.P0.ravel().copy()
        P[self.free] = x
        return P.reshape(self.n, self.d)

    def x0(self):
        return self.P0.ravel()[self.free].copy()

    def jacobian_full(self, P):
        n, d = self.n, self.d
        if self.kind == "body_hinge":
            m = len(self.E)
            J = np.zeros((m + d * len(self.held), n, d))
            D = 2 * (P[self.E[:, 0]] - P[self.E[:, 1]]) / self.s ** 2
            r = np.arange(m)
            J[r, self.E[:, 0]] += D
            J[r, self.E[:, 1]] -= D
            row = m
            for v, f, lam in self.held:
                for k in range(d):
                    J[row, v, k] += 1.0 / self.s
                    for fi, l in zip(f, lam):
                        J[row, fi, k] -= l / self.s
                    row += 1
            return J.reshape(-1, n * d)
        if self.kind in ("framework", "sphere_packing"):
            m = len(self.E)
            J = np.zeros((m, n, d))
            D = 2 * (P[self.E[:, 0]] - P[self.E[:, 1]]) / self.s ** 2
            r = np.arange(m)
            J[r, self.E[:, 0]] += D
            J[r, self.E[:, 1]] -= D
            return J.reshape(m, n * d)
        if self.kind == "angular_framework":
            m = len(self.A)
            J = np.zeros((m, n, d))
            a = P[self.A[:, 0]] - P[self.A[:, 1]]
            b = P[self.A[:, 2]] - P[self.A[:, 1]]
            na = np.linalg.norm(a, axis=1)[:, None]
            nb = np.linalg.norm(b, axis=1)[:, None]
            ab = np.sum(a * b, axis=1)[:, None]
            ga = b / (na * nb) - ab * a / (na ** 3 * nb)
            gb = a / (na * nb) - ab * b / (na * nb ** 3)
            r = np.arange(m)
            J[r, self.A[:, 0]] += ga
            J[r, self.A[:, 2]] += gb
            J[r, self.A[:, 1]] -= ga + gb
            return J.reshape(m, n * d)
        m = len(self.S)
        J = np.zeros((m, n, d))
        Pm = P[self.S]
        M = Pm[:, 1:, :] - Pm[:, :1, :]  # rows p_k - p_0, k = 1..d
        r = np.arange(m)
        # d det(M) / d M = cofactor matrix, computed without inverting (M may be singular)
        cof = np.zeros_like(M)
        for i in range(d):
            for j in range(d):
                minor = np.delete(np.delete(M, i, axis=1), j, axis=2)
                cof[:, i, j] = (-1) ** (i + j) * (np.linalg.det(minor) if d > 1 else 1.0)
        cof /= self.s ** d
        for k in range(1, d + 1):
            J[r, self.S[:, k]] += cof[:, k - 1, :]
            J[r, self.S[:, 0]] -= cof[:, k - 1, :]
        return J.reshape(m, n * d)

    def jacobian(self, x):
        return self.jacobian_full(self.config(x))[self.eq_keep][:, self.free]

    # -- trivial motions
    def generators(self, P):
        if self.kind == "angular_framework":
            return similarity_generators(P)
        if self.kind == "volume_hypergraph":
            return equiaffine_generators(P)
        return euclid_generators(P)

    def trivial_basis(self, x):
        """Orthonormal basis (columns, free coordinates) of the trivial flexes that fix the pins."""
        G = self.generators(self.config(x))
        G = G / np.maximum(np.linalg.norm(G, axis=1, keepdims=True), 1e-300)
        if len(self.pincols):
            N = _null(G[:, self.pincols].T)  # coefficient vectors that keep the pins still
            T = G[:, self.free].T @ N
        else:
            T = G[:, self.free].T
        return _orth(T)

    # -- invariants of the trivial group (for the tracker's "moved" test)
    def invariant(self, P):
        if self.kind == "volume_hypergraph":
            trip = list(itertools.combinations(range(self.n), self.d + 1))
            if len(trip) > 4000:
                trip = trip[:4000]
            S = np.array(trip)
            M = P[S][:, 1:, :] - P[S][:, :1, :]
            return np.linalg.det(M) / self.s ** self.d
        iu = np.triu_indices(self.n, 1)
        D = np.linalg.norm(P[iu[0]] - P[iu[1]], axis=1)
        if self.kind == "angular_framework" and not self.pinned:
            return D / D.max()
        return D / self.s

    # -- counts
    def counts(self):
        """dict with variables, equations, rank, trivial, nontrivial, stress, clear, sv info."""
        x = self.x0()
        J = self.jacobian(x)
        nv = J.shape[1]
        m = J.shape[0]
        out = {"variables": nv, "equations": m}
        if m == 0:
            rank, clear, lo, hi = 0, True, None, None
        else:
            norms = np.linalg.norm(J, axis=1, keepdims=True)
            Jn = J / np.maximum(norms, 1e-300)
            s = np.linalg.svd(Jn, compute_uv=False)
            smax = s[0]
            kept = s[s > KEEP * smax]
            dropped = s[s <= KEEP * smax]
            rank = len(kept)
            lo = float(kept[-1] / smax)
            hi = float(dropped[0] / smax) if len(dropped) else 0.0
            clear = hi < DROP and bool(np.all(norms > 0))
        T = self.trivial_basis(x)
        trivial = T.shape[1]
        out.update(rank=rank, trivial=trivial, nontrivial=nv - rank - trivial, stress=m - rank,
                   clear=clear, sigma_kept_min=lo, sigma_dropped_max=hi)
        # the trivial flexes must lie in the kernel (a check of this oracle itself)
        if trivial:
            out["trivial_in_kernel"] = float(np.abs(J @ T).max() / max(np.abs(J).max(), 1e-300))
        else:
            out["trivial_in_kernel"] = 0.0
        return out

    # -- the tracker
    def nontrivial_kernel(self, x, rank):
        J = self.jacobian(x)
        Jn = J / np.maximum(np.linalg.norm(J, axis=1, keepdims=True), 1e-300)
        if J.shape[1] <= BIG:
            _, s, Vt = np.linalg.svd(Jn)
            K = Vt[rank:].T
        else:  # faster for large systems: the eigenvectors of J^T J with the smallest eigenvalues
            w, V = np.linalg.eigh(Jn.T @ Jn)
            K = V[:, :J.shape[1] - rank]
        T = self.trivial_basis(x)
        if T.shape[1]:
            K = K - T @ (T.T @ K)
        return _orth(K, rel=1e-6)

    def correct(self, x, rank=None, iters=30, tol=1e-13):
        """Gauss-Newton with the rank-truncated pseudo-inverse (the rank of the start: along a
        family of realizations of constant rank this converges even where the equations are
        redundant, e.g. in Dixon's mechanism); rank None: plain min-norm least squares. The
        factorization is reused while the residual falls by 4x per iteration (chord steps); steps
        are capped at a quarter of the extent."""
        with np.errstate(all="ignore"):
            r = self.residual(x)
            fac = None
            prev = np.inf
            for _ in range(iters):
                if not np.all(np.isfinite(r)):
                    return x, np.inf
                nr = float(np.abs(r).max()) if r.size else 0.0
                if nr <= tol:
                    break
                if fac is None or nr > 0.25 * prev:
                    J = self.jacobian(x)
                    if not np.all(np.isfinite(J)):
                        return x, np.inf
                    if J.shape[1] <= BIG:
                        U, sv, Vt = np.linalg.svd(J, full_matrices=False)
                        k = int(np.sum(sv > (1e-14 if rank is not None else 1e-12) * sv[0]))
                        if rank is not None:
                            k = max(1, min(rank, k))
                        fac = (U[:, :k], sv[:k], Vt[:k], None)
                    else:  # large: J^+ r = J^T (J J^T)^+ r, (J J^T)^+ truncated to the rank
                        lam, Q = np.linalg.eigh(J @ J.T)
                        k = int(np.sum(lam > (1e-24 if rank is not None else 1e-20) * lam[-1]))
                        if rank is not None:
                            k = max(1, min(rank, k))
                        fac = (Q[:, -k:], lam[-k:], None, J)
                prev = nr
                U, sv, Vt, Jf = fac
                if Jf is None:
                    dx = -Vt.T @ ((U.T @ r) / sv)
                else:
                    dx = -Jf.T @ (U @ ((U.T @ r) / sv))
                nd = np.linalg.norm(dx)
                if nd > 0.25 * self.s:
                    dx *= 0.25 * self.s / nd
                x = x + dx
                r = self.residual(x)
            return x, float(np.abs(r).max()) if r.size else 0.0

    def track(self, rng, rank, steps=4, h=0.015, valid=None, max_basis=6):
        """Follow a nontrivial kernel direction. Returns (moved, change, residual, note)."""
        x0 = self.x0()
        K = self.nontrivial_kernel(x0, rank)
        if K.shape[1] == 0:
            return False, 0.0, 0.0, "no nontrivial kernel"
        inv0 = self.invariant(self.config(x0))
        step = h * self.s
        best = (False, 0.0, 0.0, "not tried")
        # directions: a random combination first, then the basis directions (at a singular start
        # a random direction may leave the realization space while a basis direction stays in it)
        dirs = [K @ rng.standard_normal(K.shape[1])]
        if K.shape[1] > 1:
            dirs += [K[:, j] for j in range(min(K.shape[1], max_basis))]
        for v0 in dirs:
            v0 = v0 / self._vmax(v0)
            r = self._track_dir(x0, v0, inv0, step, steps, rank, valid)
            if r[0]:
                return r
            if r[1] >= best[1]:
                best = r
        return best

    def _change(self, x, inv0):
        """Relative change of the trivial group's invariants (0: still on the start's orbit)."""
        return float(np.abs(self.invariant(self.config(x)) - inv0).max() / max(np.abs(inv0).max(), 1e-300))

    def _vmax(self, v):
        """The largest displacement of one vertex (steps are measured by it)."""
        return max(float(np.linalg.norm(v.reshape(-1, self.d), axis=1).max()), 1e-300)

    def _track_dir(self, x0, v0, inv0, step, steps, rank, valid):
        best = (False, 0.0, 0.0, "not tried")
        for sign in (1.0, -1.0):
            x, v = x0.copy(), sign * v0
            res, accepted, note = 0.0, 0, "moved"
            for it in range(3 * steps):
                if it >= steps and self._change(x, inv0) > 1e-3:
                    break  # enough; more steps only while the change is still below the threshold
                y, r = self.correct(x + step * v, rank)
                if r > 1e-10 or not np.all(np.isfinite(y)):
                    # the rank changes near here (a singular start): plain min-norm Gauss-Newton
                    y, r = self.correct(x + step * v, None, iters=300)
                if r > 1e-10 or not np.all(np.isfinite(y)):
                    note = "corrector failed"
                    break
                if valid is not None and not valid(self.config(y)):
                    note = "left the valid region"
                    break
                x, res, accepted = y, r, accepted + 1
                Kn = self.nontrivial_kernel(y, rank)
                if Kn.shape[1] == 0:
                    note = "no nontrivial kernel on the way"
                    break
                w = Kn @ (Kn.T @ v)
                if self._vmax(w) < 1e-3 * self._vmax(v):
                    note = "direction lost"
                    break
                v = w / self._vmax(w)
            change = self._change(x, inv0)
            if accepted and res <= 1e-10 and change > 1e-3:
                return True, change, res, "moved"
            if change >= best[1]:
                best = (False, change, res, note if note != "moved" else "did not leave the orbit")
        return best
