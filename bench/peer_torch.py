#!/usr/bin/python3
"""The PyTorch peer of bench_iteration: one training iteration of the full
single-shape method (Table 1 row 11) on the CPU, with our architecture, losses
and weights, in two forms.

  authors  as the authors wrote it: the Jacobian of phi by torch.autograd.grad
           with create_graph=True, one call per output coordinate (three
           double-backward passes); Chamfer through autograd on the full pairwise
           squared-distance matrix; repulsion as the full K x K exp through
           autograd.
  best     the fastest form we could write: the Jacobian by stacked forward
           mode, rows [x; dx/du; dx/dv] through each layer as one GEMM (bias on
           the value rows, ReLU mask from them), as model/mlp.cpp does; nearest
           neighbours found without autograd (blocked GEMM distances, one pass
           for both directions), the loss then differentiable on the matched
           pairs; repulsion cut off where exp(-d/sigma) < 1e-7 (a grid, as
           losses/repulsion.cpp) with its gradient computed in the same pass.

The model (see model/objective.cpp, single_shape_objective):
  x_P = mu_i + sigma e              K Gaussians, sigma = 1/sqrt(K)     (Eq. 4)
  u_S = psi(x_S, alpha n_S)          psi: 6 -> width^depth -> 2
  phi on [x_P; u_S] with J = [J_u, J_v]; n = alpha (J_u x J_v)/|.|, phi6 = [phi, n]
  L = L_6D + 1e-2 L_2D + L_cycle(2D) + L_cycle(6D) + 1e-4 L_iso + L_rep   (Eq. 5)
Every term a mean over its points; Chamfer the sum of the two directions' mean
squared nearest distance (losses/chamfer.h); then Adam (lr 1e-3).

Run it with its best BLAS (see the issue and bench/harness.sh):
  env -u OPENBLAS_CORETYPE -u OPENBLAS_L2_SIZE \\
      LD_LIBRARY_PATH=/usr/lib/x86_64-linux-gnu/openblas-openmp \\
      /usr/bin/python3 bench/peer_torch.py --form both --points 10000 --gaussians 10000 --width 256

  --selftest  checks that both forms give the same loss and gradients (float64,
              M = K = 64, width 16) and exits.
"""
import argparse
import ctypes
import json
import math
import os
import statistics
import sys
import time


def parse():
    p = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    p.add_argument("--form", choices=["authors", "best", "both"], default="both")
    p.add_argument("--points", type=int, default=2500, help="M, points per step on P and on the shape")
    p.add_argument("--gaussians", type=int, default=2500, help="K, Gaussians of the domain")
    p.add_argument("--width", type=int, default=128)
    p.add_argument("--depth", type=int, default=5, help="hidden layers")
    p.add_argument("--threads", type=int, default=2)
    p.add_argument("--iters", type=int, default=5, help="timed iterations")
    p.add_argument("--warmup", type=int, default=2, help="untimed iterations first")
    p.add_argument("--json", help="append one JSON line per form to this file")
    p.add_argument("--selftest", action="store_true")
    a = p.parse_args()
    for k in ("points", "gaussians", "width", "depth", "threads", "iters"):
        if getattr(a, k) < 1:
            p.error(f"--{k} must be positive")
    if a.warmup < 0:
        p.error("--warmup must be >= 0")
    return a


ARGS = parse()
# Before torch loads: OpenMP (torch's and OpenBLAS-openmp's) reads it at start-up.
os.environ["OMP_NUM_THREADS"] = str(ARGS.threads)
import torch  # noqa: E402

ALPHA = 0.01
WEIGHTS = dict(surface=1.0, chart=1e-2, cycle=1.0, isometry=1e-4, repulsion=1.0)  # model/objective.h
REPULSION_TOLERANCE = 1e-7
TIMERS = {}  # seconds spent in named kernels during the current iteration (best form)


class timed:
    def __init__(self, name):
        self.name = name

    def __enter__(self):
        self.t0 = time.perf_counter()

    def __exit__(self, *exc):
        TIMERS[self.name] = TIMERS.get(self.name, 0.0) + time.perf_counter() - self.t0


# ---------------------------------------------------------------- BLAS report

def blas_report():
    """Which BLAS library and kernel torch runs on, read from the process itself."""
    a = torch.randn(64, 64)
    (a @ a).sum().item()  # make sure the BLAS is loaded and initialised
    libs = []
    with open("/proc/self/maps") as f:
        for line in f:
            path = line.split()[-1] if len(line.split()) >= 6 else ""
            name = os.path.basename(path)
            if ("blas" in name or "lapack" in name or "mkl" in name) and path not in libs:
                libs.append(path)
    info = {"libraries": libs, "openblas_config": None, "openblas_core": None,
            "openblas_parallel": None, "openblas_threads": None}
    for path in libs:
        try:
            lib = ctypes.CDLL(path)  # already loaded: the same handle
        except OSError:
            continue
        if not hasattr(lib, "openblas_get_config"):
            continue
        lib.openblas_get_config.restype = ctypes.c_char_p
        lib.openblas_get_corename.restype = ctypes.c_char_p
        info["openblas_library"] = path
        info["openblas_config"] = lib.openblas_get_config().decode()
        info["openblas_core"] = lib.openblas_get_corename().decode()
        info["openblas_parallel"] = {0: "sequential", 1: "pthreads", 2: "openmp"}.get(
            lib.openblas_get_parallel(), "unknown")
        info["openblas_threads"] = lib.openblas_get_num_threads()
        break
    return info


def print_environment():
    print("torch", torch.__version__, "| threads", torch.get_num_threads(),
          "| OMP_NUM_THREADS", os.environ.get("OMP_NUM_THREADS"))
    print(torch.__config__.show().rstrip())
    print(torch.__config__.parallel_info().rstrip())
    info = blas_report()
    print("BLAS libraries mapped:", ", ".join(info["libraries"]) or "none")
    if info["openblas_config"]:
        print(f"OpenBLAS: {info['openblas_library']}\n  config: {info['openblas_config']}\n"
              f"  kernel: {info['openblas_core']}  threading: {info['openblas_parallel']}"
              f"  threads: {info['openblas_threads']}")
    warnings = []
    if not info["openblas_config"]:
        warnings.append("torch is not running on OpenBLAS (reference BLAS is ~20x slower): "
                        "install libopenblas0-openmp and set LD_LIBRARY_PATH")
    elif info["openblas_parallel"] != "openmp":
        warnings.append("OpenBLAS is the %s build, which fights torch's OpenMP threads: use "
                        "LD_LIBRARY_PATH=/usr/lib/x86_64-linux-gnu/openblas-openmp"
                        % info["openblas_parallel"])
    for var in ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE"):
        if var in os.environ:
            warnings.append(f"{var}={os.environ[var]} is set: it can force a slower kernel "
                            "(run under env -u " + var + ")")
    for w in warnings:
        print("WARNING:", w)
    info["warnings"] = warnings
    info["env"] = {v: os.environ.get(v) for v in ("OPENBLAS_CORETYPE", "OPENBLAS_L2_SIZE",
                                                    "LD_LIBRARY_PATH", "OMP_NUM_THREADS")}
    return info


# ---------------------------------------------------------------- the model

class Atlas:
    """phi (2 -> 3), psi (6 -> 2) as nn.Linear stacks with PyTorch's default
    initialisation (U(-1/sqrt(in), 1/sqrt(in)), as model/mlp.cpp), and the means
    mu ~ U([0, 1]^2) of K Gaussians with sigma = 1/sqrt(K) (model/domain.cpp)."""

    def __init__(self, gaussians, width, depth, dtype, seed=0):
        torch.manual_seed(seed)

        def mlp(n_in, n_out):
            sizes = [n_in] + [width] * depth + [n_out]
            return [torch.nn.Linear(a, b).to(dtype) for a, b in zip(sizes[:-1], sizes[1:])]

        self.phi = mlp(2, 3)
        self.psi = mlp(6, 2)
        self.mu = torch.nn.Parameter(torch.rand(gaussians, 2, dtype=dtype))
        self.sigma = 1.0 / math.sqrt(gaussians)

    def parameters(self):
        out = [self.mu]
        for layer in self.phi + self.psi:
            out += [layer.weight, layer.bias]
        return out


class Data:
    """A pool of points on the unit sphere with alpha-scaled normals (the cost
    does not depend on the shape), and the per-step draws: M target rows, M
    component indices, M noise vectors."""

    def __init__(self, points, gaussians, dtype, pool=200000, seed=1):
        self.g = torch.Generator().manual_seed(seed)
        p = torch.randn(pool, 3, generator=self.g, dtype=dtype)
        p /= p.norm(dim=1, keepdim=True)
        self.pool = torch.cat([p, ALPHA * p], dim=1)
        self.m, self.k = points, gaussians

    def draw(self):
        rows = torch.randint(self.pool.shape[0], (self.m,), generator=self.g)
        comp = torch.randint(self.k, (self.m,), generator=self.g)
        noise = torch.randn(self.m, 2, generator=self.g, dtype=self.pool.dtype)
        return self.pool[rows], comp, noise


def weighted_total(t):
    w = WEIGHTS
    return (w["surface"] * t["surface"] + w["chart"] * t["chart"] + w["cycle"] * t["cycle_2d"]
            + w["cycle"] * t["cycle_6d"] + w["isometry"] * t["isometry"]
            + w["repulsion"] * t["repulsion"])


def isometry(ju, jv):
    """Eq. 10, losses/isometry.h: mean (E - 1)^2 + 2 F^2 + (G - 1)^2."""
    e = (ju * ju).sum(1) - 1
    g = (jv * jv).sum(1) - 1
    f = (ju * jv).sum(1)
    return (e * e + g * g + 2 * f * f).mean()


def normals(ju, jv):
    """Eq. 2 with model/parametrize.cpp's row_normalize (eps 1e-12 under the root)."""
    c = torch.cross(ju, jv, dim=1)
    return ALPHA * c / torch.sqrt((c * c).sum(1, keepdim=True) + 1e-12)


def mean_squared_distance(a, b):
    return ((a - b) ** 2).sum(1).mean()


def objective(atlas, batch, phi_jacobian, psi, chamfer, repulsion):
    """single_shape_objective with the form's pieces plugged in; returns the
    weighted total and the unweighted terms."""
    targets, comp, noise = batch
    m = targets.shape[0]
    x_p = atlas.mu[comp] + atlas.sigma * noise          # Eq. 4, reparameterized
    u_s = psi(atlas.psi, targets)                       # psi(x_S, alpha n_S)
    phi, ju, jv = phi_jacobian(atlas.phi, torch.cat([x_p, u_s]))
    phi6 = torch.cat([phi, normals(ju, jv)], dim=1)     # Eq. 3
    t = {}
    t["surface"] = chamfer(phi6[:m], targets)          # Eq. 7
    t["chart"] = chamfer(u_s, x_p)                     # Eq. 8
    t["cycle_2d"] = mean_squared_distance(x_p, psi(atlas.psi, phi6[:m]))  # Eq. 9
    t["cycle_6d"] = mean_squared_distance(targets, phi6[m:])
    t["isometry"] = isometry(ju[:m], jv[:m])           # Eq. 10
    t["repulsion"] = repulsion(atlas.mu, atlas.sigma)  # Eq. 11
    return weighted_total(t), t


# ---------------------------------------------------------------- authors' form

def mlp_plain(layers, x):
    for layer in layers[:-1]:
        x = torch.relu(layer(x))
    return layers[-1](x)


def phi_jacobian_autograd(layers, x):
    """phi and its Jacobian by reverse mode: one autograd.grad per output
    coordinate with create_graph=True, so backward differentiates through them."""
    y = mlp_plain(layers, x)
    rows = [torch.autograd.grad(y[:, c].sum(), x, create_graph=True)[0] for c in range(3)]
    jac = torch.stack(rows, dim=1)  # N x 3 x 2: d y_c / d (u, v)
    return y, jac[:, :, 0], jac[:, :, 1]


def chamfer_full_matrix(a, b):
    """|a_i|^2 + |b_j|^2 - 2 a_i.b_j for all pairs, min both ways, through autograd
    (AtlasNet's distChamfer, which the authors' code builds on)."""
    d = (a * a).sum(1)[:, None] + (b * b).sum(1)[None, :] - 2 * a @ b.t()
    return d.min(1)[0].mean() + d.min(0)[0].mean()


def repulsion_full(mu, sigma):
    """1/K^2 sum_{i,j} exp(-|mu_i - mu_j| / sigma), every pair, through autograd
    (the norm's pull-back is 0 at the coincident i = j pairs, as ours)."""
    d = torch.linalg.vector_norm(mu[:, None, :] - mu[None, :, :], dim=2)
    return torch.exp(-d / sigma).mean()


def loss_authors(atlas, batch):
    return objective(atlas, batch, phi_jacobian_autograd, mlp_plain, chamfer_full_matrix,
                     repulsion_full)


# ---------------------------------------------------------------- best form

class StackedLinear(torch.autograd.Function):
    """One layer on stacked rows h = [value (n rows); tangents (n rows each)]:
    z = h W^T (one GEMM), + b on the value rows, then (relu) every block zeroed
    where the value rows have z <= 0 (the value rows' ReLU mask, model/mlp.cpp).
    The pull-back is written out: the mask, two GEMMs and the bias sum over the
    value rows."""

    @staticmethod
    def forward(ctx, h, weight, bias, n, relu):
        z = torch.mm(h, weight.t())
        z[:n] += bias
        off = None
        if relu:
            off = z[:n] <= 0
            z.view(-1, n, z.shape[1]).masked_fill_(off, 0)
        ctx.n = n
        ctx.save_for_backward(h, weight, off)
        return z

    @staticmethod
    def backward(ctx, g):
        h, weight, off = ctx.saved_tensors
        n = ctx.n
        if off is not None:
            g = g.view(-1, n, g.shape[1]).masked_fill(off, 0).view(g.shape)
        dh = torch.mm(g, weight) if ctx.needs_input_grad[0] else None
        return dh, torch.mm(g.t(), h), g[:n].sum(0), None, None


def mlp_stacked(layers, h, n):
    for k, layer in enumerate(layers):
        h = StackedLinear.apply(h, layer.weight, layer.bias, n, k + 1 < len(layers))
    return h


def phi_jacobian_stacked(layers, x):
    """[x; e_u; e_v] (3N x 2) -> [phi; J_u; J_v] in one pass (engine/tangents.h)."""
    n = x.shape[0]
    e = torch.zeros(2 * n, 2, dtype=x.dtype)
    e[:n, 0] = 1
    e[n:, 1] = 1
    y = mlp_stacked(layers, torch.cat([x, e]), n)
    return y[:n], y[n:2 * n], y[2 * n:]


def psi_fused(layers, x):
    return mlp_stacked(layers, x, x.shape[0])


BLOCK_ELEMENTS = 1 << 19  # distance entries per block of the nearest-neighbour search
CHUNK = 1024  # columns per chunk of the row-wise search


@torch.no_grad()
def nearest_both(a, b):
    """a_i's nearest row of b and b_j's nearest row of a, in one blocked pass over
    the squared distances |a_i|^2 + |b_j|^2 - 2 a_i.b_j (one GEMM per block of
    rows of a). torch's index-returning reductions (argmin, min(dim)) are several
    times slower than amin, so the indices are found in two levels:
      rows of a: amin over column chunks, argmin over the few chunk minima, then
                 argmin inside the winning chunk only;
      columns:   amin over the block's rows, carried across blocks with the block
                 that holds it; at the end each b_j is compared with the rows of
                 its best block only (exact differences)."""
    n, m = a.shape[0], b.shape[0]
    if n * m <= BLOCK_ELEMENTS:  # one small block: the plain reductions
        d = torch.addmm(((b * b).sum(1))[None, :], a, b.t(), alpha=-2)
        to_b = d.argmin(1)
        d += (a * a).sum(1)[:, None]
        return to_b, d.argmin(0)
    chunks = max(1, m // CHUNK)
    width = -(-m // chunks)  # ceil: chunks x width >= m columns
    if chunks * width > m:   # pad b with points no row is ever nearest to
        b = torch.cat([b, torch.full((chunks * width - m, b.shape[1]), 1e15, dtype=b.dtype)])
    a2, b2 = (a * a).sum(1), (b * b).sum(1)
    rows = min(n, max(1, BLOCK_ELEMENTS // b.shape[0]))
    to_b = torch.empty(n, dtype=torch.long)
    best = torch.full((b.shape[0],), math.inf, dtype=a.dtype)
    best_block = torch.zeros(b.shape[0], dtype=torch.long)
    bt = b.t()
    for blk, s in enumerate(range(0, n, rows)):
        e = min(n, s + rows)
        d = torch.addmm(b2[None, :], a[s:e], bt, alpha=-2)       # |b_j|^2 - 2 a_i.b_j
        d3 = d.view(e - s, chunks, width)
        c = d3.amin(2).argmin(1)                                  # each row's best chunk
        to_b[s:e] = c * width + d3[torch.arange(e - s), c].argmin(1)
        d += a2[s:e, None]                                        # |a_i - b_j|^2
        v = d.amin(0)
        better = v < best
        best = torch.where(better, v, best)
        best_block = torch.where(better, blk, best_block)
    b = b[:m]
    cand = (best_block[:m, None] * rows + torch.arange(rows)).clamp_(max=n - 1)  # m x rows
    dist = ((a[cand] - b[:, None, :]) ** 2).sum(2)
    to_a = cand.gather(1, dist.argmin(1, keepdim=True)).squeeze(1)
    return to_b, to_a


def chamfer_matched(a, b):
    with timed("nearest"):
        to_b, to_a = nearest_both(a.detach(), b.detach())
    return mean_squared_distance(a, b[to_b]) + mean_squared_distance(b, a[to_a])


@torch.no_grad()
def repulsion_cutoff(mu, sigma, tolerance=REPULSION_TOLERANCE):
    """L_rep and dL/dmu over the pairs closer than r_c = sigma ln(1/tolerance)
    (dropped pairs: exp(-d/sigma) < tolerance each), on a grid of cells of side
    >= r_c: each cell against its 3 x 3 neighbourhood, one vectorised block each."""
    k = mu.shape[0]
    r_c = sigma * math.log(1.0 / tolerance) * (1 + 1e-9)
    lo = mu.min(0).values
    span = (mu.max(0).values - lo).tolist()
    h = r_c
    while (span[0] / h + 1) * (span[1] / h + 1) > 4 * k + 16:
        h *= 2
    nx, ny = int(span[0] / h) + 1, int(span[1] / h) + 1
    cell_xy = ((mu - lo) / h).long()
    cx = cell_xy[:, 0].clamp_(0, nx - 1)
    cy = cell_xy[:, 1].clamp_(0, ny - 1)
    cell = cy * nx + cx
    order = torch.argsort(cell, stable=True)
    p = mu[order]
    start = [0] + torch.cumsum(torch.bincount(cell, minlength=nx * ny), 0).tolist()
    rows = torch.empty(k, dtype=torch.float64)
    grad = torch.empty(k, 2, dtype=mu.dtype)
    tiny = torch.finfo(mu.dtype).tiny
    for c in range(nx * ny):
        s0, s1 = start[c], start[c + 1]
        if s0 == s1:
            continue
        x, y = c % nx, c // nx
        x0, x1 = max(0, x - 1), min(nx - 1, x + 1)
        cand = torch.cat([p[start[ry * nx + x0]:start[ry * nx + x1 + 1]]
                          for ry in range(max(0, y - 1), min(ny - 1, y + 1) + 1)])
        dx = p[s0:s1, 0:1] - cand[:, 0]
        dy = p[s0:s1, 1:2] - cand[:, 1]
        d = torch.addcmul(dx * dx, dy, dy).sqrt_()
        w = torch.mul(d, -1.0 / sigma).exp_()
        rows[s0:s1] = w.sum(1, dtype=torch.float64)
        w /= d.clamp_min_(tiny)  # w_ij / d_ij; the d_ij = 0 terms multiply dx = dy = 0
        grad[s0:s1, 0] = torch.einsum("ij,ij->i", w, dx)
        grad[s0:s1, 1] = torch.einsum("ij,ij->i", w, dy)
    out = torch.empty_like(grad)
    out[order] = grad * (-2.0 / (sigma * k * k))
    return rows.sum().item() / (k * k), out


class Repulsion(torch.autograd.Function):
    """Value and gradient in the forward pass; the pull-back only scales."""

    @staticmethod
    def forward(ctx, mu, sigma):
        value, grad = repulsion_cutoff(mu.detach(), sigma)
        ctx.save_for_backward(grad)
        return torch.tensor(value, dtype=mu.dtype)

    @staticmethod
    def backward(ctx, g):
        (grad,) = ctx.saved_tensors
        return g * grad, None


def repulsion_fused(mu, sigma):
    with timed("repulsion"):
        return Repulsion.apply(mu, sigma)


def loss_best(atlas, batch):
    return objective(atlas, batch, phi_jacobian_stacked, psi_fused, chamfer_matched,
                     repulsion_fused)


FORMS = {"authors": (loss_authors, {}), "best": (loss_best, {"foreach": True})}


# ---------------------------------------------------------------- driver

def time_form(form, a, blas):
    loss_fn, adam_options = FORMS[form]
    atlas = Atlas(a.gaussians, a.width, a.depth, torch.float32)
    data = Data(a.points, a.gaussians, torch.float32)
    opt = torch.optim.Adam(atlas.parameters(), lr=1e-3, **adam_options)
    seconds, pieces = [], []
    for it in range(a.warmup + a.iters):
        TIMERS.clear()
        t0 = time.perf_counter()
        batch = data.draw()
        opt.zero_grad(set_to_none=True)
        loss, _ = loss_fn(atlas, batch)
        loss.backward()
        opt.step()
        dt = time.perf_counter() - t0
        if not math.isfinite(loss.item()):
            raise SystemExit(f"{form}: non-finite loss at iteration {it}")
        if it >= a.warmup:
            seconds.append(dt)
            pieces.append(dict(TIMERS))
    med = statistics.median(seconds)
    breakdown = {k: statistics.median(p[k] for p in pieces) for k in pieces[0]} if pieces[0] else {}
    extra = "".join(f", {k} {v:.4f} s" for k, v in breakdown.items())
    print(f"torch {form:8s} M={a.points} K={a.gaussians} {a.depth}x{a.width} threads={a.threads}: "
          f"median {med:.4f} s/iter over {a.iters} (min {min(seconds):.4f}, max {max(seconds):.4f})"
          f"{extra}", flush=True)
    if a.json:
        rec = dict(peer="torch", form=form, points=a.points, gaussians=a.gaussians, width=a.width,
                   depth=a.depth, threads=a.threads, warmup=a.warmup, iters=a.iters,
                   median_s=med, seconds=seconds, breakdown_s=breakdown, torch=torch.__version__,
                   blas=blas.get("openblas_library") or ",".join(blas["libraries"]),
                   openblas_config=blas["openblas_config"], openblas_core=blas["openblas_core"],
                   openblas_parallel=blas["openblas_parallel"], warnings=blas["warnings"])
        with open(a.json, "a") as f:
            f.write(json.dumps(rec) + "\n")


def gradients(loss_fn, atlas, batch):
    for q in atlas.parameters():
        q.grad = None
    loss, terms = loss_fn(atlas, batch)
    loss.backward()
    return loss.item(), {k: float(v) for k, v in terms.items()}, [q.grad.clone() for q in atlas.parameters()]


def selftest(dtype, tolerance):
    """Both forms on the same parameters and draws: same terms, same gradients."""
    atlas = Atlas(64, 16, 5, dtype)
    data = Data(64, 64, dtype, pool=1000)
    names = ["mu"] + [f"{net}.{kind}{k}" for net, layers in (("phi", atlas.phi), ("psi", atlas.psi))
                      for k in range(len(layers)) for kind in ("w", "b")]
    worst = 0.0
    for step in range(2):
        batch = data.draw()
        la, ta, ga = gradients(loss_authors, atlas, batch)
        lb, tb, gb = gradients(loss_best, atlas, batch)
        print(f"  {dtype} draw {step}: loss authors {la:.12g}  best {lb:.12g}  "
              f"(rel diff {abs(la - lb) / abs(la):.2e})")
        print("    terms authors " + " ".join(f"{k}={v:.6g}" for k, v in ta.items()))
        print("    terms best    " + " ".join(f"{k}={v:.6g}" for k, v in tb.items()))
        rel = [abs(la - lb) / abs(la)] + [abs(ta[k] - tb[k]) / max(abs(ta[k]), 1e-30) for k in ta]
        for name, x, y in zip(names, ga, gb):
            if not (torch.isfinite(x).all() and torch.isfinite(y).all()):
                raise SystemExit(f"selftest: non-finite gradient of {name}")
            rel.append(((x - y).abs().max() / x.abs().max().clamp_min(1e-30)).item())
        worst = max(worst, max(rel))
        gi = max(range(len(names)), key=lambda i: rel[1 + len(ta) + i])
        print(f"    gradients: {len(names)} tensors, worst relative max-difference "
              f"{rel[1 + len(ta) + gi]:.2e} ({names[gi]})")
        # take a step so the second draw is checked away from the initialisation
        with torch.no_grad():
            for q, g in zip(atlas.parameters(), ga):
                q -= 1e-2 * g
    ok = worst <= tolerance
    print(f"  {dtype}: worst relative difference {worst:.2e} (tolerance {tolerance:g}): "
          f"{'ok' if ok else 'FAILED'}")
    return ok


def selftest_kernels():
    """The best form's kernels where the tiny model does not reach them: several
    blocks, chunks and padding in the search, several grid cells in repulsion."""
    g = torch.Generator().manual_seed(5)
    ok = True
    for n, m, c in ((3000, 2500, 6), (2100, 3100, 2)):
        a = torch.randn(n, c, generator=g, dtype=torch.float64)
        b = torch.randn(m, c, generator=g, dtype=torch.float64)
        to_b, to_a = nearest_both(a, b)
        d = torch.cdist(a, b, compute_mode="donot_use_mm_for_euclid_dist")
        same = bool((d.argmin(1) == to_b).all()) and bool((d.argmin(0) == to_a).all())
        print(f"  nearest_both {n} x {m} {c}D == brute force: {'ok' if same else 'FAILED'}")
        ok &= same
    k = 2000
    mu = torch.rand(k, 2, generator=g, dtype=torch.float64).requires_grad_()
    exact = repulsion_full(mu, 1 / math.sqrt(k))
    exact.backward()
    value, grad = repulsion_cutoff(mu.detach(), 1 / math.sqrt(k))
    ev = abs(value - exact.item()) / exact.item()
    eg = ((grad - mu.grad).abs().max() / mu.grad.abs().max()).item()
    good = ev < 1e-6 and eg < 1e-6
    print(f"  repulsion cut-off K = {k} vs every pair: value {ev:.1e}, gradient {eg:.1e} relative: "
          f"{'ok' if good else 'FAILED'}")
    return ok and good


def main():
    a = ARGS
    torch.set_num_threads(a.threads)
    blas = print_environment()
    if a.selftest:
        print("selftest: authors vs best, M = K = 64, width 16, depth 5")
        ok = selftest(torch.float64, 1e-4)
        ok32 = selftest(torch.float32, 1e-3)  # float32: rounding differs between the forms
        print("selftest: the best form's kernels at larger sizes (float64)")
        if not (ok and ok32 and selftest_kernels()):
            raise SystemExit("selftest FAILED")
        print("selftest passed")
        return
    forms = ["authors", "best"] if a.form == "both" else [a.form]
    for form in forms:
        time_form(form, a, blas)


if __name__ == "__main__":
    sys.exit(main())
