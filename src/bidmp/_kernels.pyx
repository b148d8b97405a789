# cython: language_level=3, boundscheck=False, wraparound=False
# cython: cdivision=True, initializedcheck=False
"""Compiled loops of a robot-protocol fit and rollout.

A fit of the robot protocol on a T = 1000 demonstration is a few hundred small array operations,
each a few microseconds of NumPy's call overhead: most of its time. The loops here do, each in
one call, what whole chains of them did:

* the decisions about the demonstration — where its straight final approach starts
  (:func:`tail_start`), over how long a window its start and end velocity are blended out
  (:func:`rest_windows`) — each a search over candidates with an early exit;
* the arithmetic the model's numbers come from — the spring's integration (:func:`second_order`,
  SciPy's ``lfilter`` operation for operation), the forcing target (:func:`forcing_target`), the
  goal gate (:func:`goal_gate`) and a path's arc length (:func:`arclength`), each element the
  same operations in the same order as the NumPy expressions they replaced (compiled without
  fused multiply-adds), so every result keeps its last bit. Powers and exponentials stay in NumPy: its vectorised ones are not the C
  library's to the bit;
* the basis products of a fit and a rollout on the rows' band (:func:`band_of`,
  :func:`band_product`, :func:`band_transposed_product`): these replaced dense BLAS products
  and round differently from them (a basis row is a dozen kernels over a floor of 1e-20; the
  dense rows were most of the memory a fit and a rollout read).

The tests check each loop against an independent reference to the last bit (SciPy's ``lfilter``,
NumPy's ``gradient`` expressions, plain searches) on random inputs.

Compiled ahead of time (a C extension built at install) rather than with numba: loading it costs
about a millisecond, where numba's import and cached kernels cost 0.1-0.3 s of every command that
fits a DMP.
"""

from libc.math cimport INFINITY, atan2, cos, fabs, floor, sin, sqrt

from numpy import array, empty


cdef void _gradient(const double[:] f, double[:] out, double dt) noexcept nogil:
    """``np.gradient(f, dt)`` of one column f (n,), n ≥ 2, operation for operation: central
    differences over ``2 dt`` inside, one-sided ones over ``dt`` at the ends."""
    cdef Py_ssize_t n = f.shape[0], i
    cdef double two_dt = 2.0 * dt
    out[0] = (f[1] - f[0]) / dt
    out[n - 1] = (f[n - 1] - f[n - 2]) / dt
    for i in range(1, n - 1):
        out[i] = (f[i + 1] - f[i - 1]) / two_dt


cdef void _running_max(double[::1] values) noexcept nogil:
    """``np.maximum.accumulate`` in place (a NaN, once met, carried on as NumPy carries it)."""
    cdef Py_ssize_t i
    for i in range(1, values.shape[0]):
        if values[i - 1] > values[i] or values[i - 1] != values[i - 1]:
            values[i] = values[i - 1]


cdef double _chord(const double[:, :] y, Py_ssize_t start, double[:] unit) noexcept nogil:
    """The length of the chord from sample ``start`` of ``y`` (T, D) to its end, and its direction
    into ``unit`` (D,); 0 when the two samples coincide (no direction)."""
    cdef Py_ssize_t last = y.shape[0] - 1, k
    cdef double length_squared = 0.0, origin_k, length
    for k in range(y.shape[1]):
        origin_k = y[start, k] - y[last, k]
        length_squared = length_squared + origin_k * origin_k
    length = sqrt(length_squared)
    if length > 0.0:
        for k in range(y.shape[1]):
            unit[k] = -(y[start, k] - y[last, k]) / length
    return length


cdef inline double _off_chord(
    const double[:, :] y, Py_ssize_t i, Py_ssize_t start, const double[:] unit, double* along
) noexcept nogil:
    """The squared distance of sample ``i`` from the chord through sample ``start`` (direction
    ``unit``), and its distance along the chord into ``along``; offsets measured from the end."""
    cdef Py_ssize_t last = y.shape[0] - 1, k
    cdef double offset_k, squared = 0.0
    along[0] = 0.0
    for k in range(y.shape[1]):
        offset_k = (y[i, k] - y[last, k]) - (y[start, k] - y[last, k])
        along[0] = along[0] + offset_k * unit[k]
        squared = squared + offset_k * offset_k
    return squared - along[0] * along[0]


cdef bint _straight_from(
    const double[:, :] y, Py_ssize_t start, double bound, const double[:] unit, Py_ssize_t stride
) noexcept nogil:
    """Whether the tail ``y[start:]`` (T, D) is straight: every sample within ``bound`` of its
    chord (direction ``unit``) and — with ``stride`` 1 — never more than that back along it. With
    ``stride`` > 1 only every ``stride``-th sample's distance is looked at (a necessary condition)."""
    cdef Py_ssize_t i = start
    cdef double along, previous = 0.0
    while i < y.shape[0]:
        if _off_chord(y, i, start, unit, &along) > bound * bound:
            return False
        if stride == 1 and i > start and along - previous < -bound:
            return False
        previous = along
        i += stride
    return True


cdef bint _probes_straight(
    const double[:, :] y, Py_ssize_t start, double bound, const double[:] unit
) noexcept nogil:
    """A necessary condition of :func:`_straight_from` from three samples of the tail (a quarter,
    half and three quarters of the way to its end), with a hair of slack for the rounding."""
    cdef Py_ssize_t last = y.shape[0] - 1, probe, index
    cdef double along
    cdef double shares[3]
    shares[0] = 0.25
    shares[1] = 0.5
    shares[2] = 0.75
    for probe in range(3):
        index = start + <Py_ssize_t>floor(shares[probe] * (last - start))
        if _off_chord(y, index, start, unit, &along) > bound * bound * (1.0 + 1e-9) + 1e-300:
            return False
    return True


def tail_start(const double[:, :] y, const long long[:] candidates, double tolerance):
    """The first of ``candidates`` (k,) — sample indices, increasing — from which the rest of ``y``
    (T, D) is straight (within ``tolerance`` × its chord of the chord, never moving back along it
    by more than that), or ``T - 1`` when none is. Three probes, then every 8th sample, then all
    of it: each stage a necessary condition of the next, each with an early exit."""
    cdef Py_ssize_t c, start, found = y.shape[0] - 1
    cdef double length, bound
    cdef double[::1] unit = empty(max(y.shape[1], 1))
    with nogil:
        for c in range(candidates.shape[0]):
            start = candidates[c]
            length = _chord(y, start, unit)
            if not length > 0.0:
                continue
            bound = tolerance * length
            if (
                _probes_straight(y, start, bound, unit)
                and _straight_from(y, start, bound, unit, 8)
                and _straight_from(y, start, bound, unit, 1)
            ):
                found = start
                break
    return found


cdef double _row_norm(const double[:, :] a, Py_ssize_t i) noexcept nogil:
    """``np.linalg.norm(a[i])``: the squares summed left to right, as NumPy does for D ≤ 8."""
    cdef Py_ssize_t k
    cdef double total = a[i, 0] * a[i, 0]
    for k in range(1, a.shape[1]):
        total = total + a[i, k] * a[i, k]
    return sqrt(total)


def rest_windows(
    const double[:, :] y,
    double dt,
    const double[:] blend_u,
    const double[:] blend_shape,
    const double[:] candidates,
    double share,
    double widest,
):
    """The rest blend's windows (normalised time) at the start and at the end of ``y`` (T, D) on
    the uniform grid ``dt``, and the demonstration's peak speed: for each end, the first of
    ``candidates`` over which blending that end's velocity out adds at most ``share`` of the
    demonstration's running peak acceleration (from that end) at every point of ``blend_u`` (the
    blend's acceleration there is ``speed · blend_shape / window``); ``widest`` when none does,
    0 when the end is at rest. Velocity and acceleration are NumPy's ``gradient`` (central
    differences, one-sided at the ends). Returns ``(start window, end window, peak speed, start
    speed, end speed)``."""
    cdef Py_ssize_t n = y.shape[0], n_dims = y.shape[1], i, k
    if n < 3:
        raise ValueError(f"rest_windows: y needs 3 samples or more, got {n}")
    cdef double[:, ::1] velocity = empty((n, n_dims))
    cdef double[:, ::1] acceleration = empty((n, n_dims))
    cdef double[::1] running_forward = empty(n)
    cdef double[::1] running_backward = empty(n)
    cdef double peak = -INFINITY, speed, start_speed, end_speed
    cdef double windows[2]
    with nogil:
        for k in range(n_dims):
            _gradient(y[:, k], velocity[:, k], dt)
            _gradient(velocity[:, k], acceleration[:, k], dt)
        for i in range(n):
            speed = _row_norm(velocity, i)
            if speed > peak or speed != speed:  # np.max: a NaN wins
                peak = speed
        # |acceleration|, as its running maximum from the start and (reversed) from the end
        for i in range(n):
            running_forward[i] = _row_norm(acceleration, i)
            running_backward[n - 1 - i] = running_forward[i]
        _running_max(running_forward)
        _running_max(running_backward)
        start_speed = _row_norm(velocity, 0)
        end_speed = _row_norm(velocity, n - 1)
        windows[0] = _blend_window(
            start_speed, running_forward, dt, peak, blend_u, blend_shape, candidates, share, widest
        )
        windows[1] = _blend_window(
            end_speed, running_backward, dt, peak, blend_u, blend_shape, candidates, share, widest
        )
    return windows[0], windows[1], peak, start_speed, end_speed


cdef double _blend_window(
    double speed,
    const double[::1] running,
    double dt,
    double peak,
    const double[:] blend_u,
    const double[:] blend_shape,
    const double[:] candidates,
    double share,
    double widest,
) noexcept nogil:
    """One end's window: the first of ``candidates`` whose blend of ``speed`` stays within
    ``share`` of the ``running`` peak acceleration (from that end) at every ``blend_u``; see
    :func:`rest_windows`."""
    cdef Py_ssize_t c, j, index, n = running.shape[0]
    # np.maximum's NaN (it propagates), as the NumPy test had it
    cdef double floor_peak = 1e-300 if 1e-300 > peak else peak
    cdef double added, reach
    if speed <= 1e-12 * floor_peak:
        return 0.0
    for c in range(candidates.shape[0]):
        for j in range(blend_u.shape[0]):
            added = speed * blend_shape[j] / candidates[c]
            index = <Py_ssize_t>(blend_u[j] * candidates[c] / dt)
            if index > n - 1:
                index = n - 1
            reach = 1e-300 if running[index] < 1e-300 else running[index]
            if not added <= share * reach:
                break
        else:
            return candidates[c]
    return widest


cdef void _filter_row(
    const double[:, :] drives,
    Py_ssize_t row,
    double[:, ::1] out,
    double b0,
    double b1,
    double b2,
    double a1,
    double a2,
    const double[:] held,
) noexcept nogil:
    """``out[row, 2:]``: SciPy's ``lfilter(b, [1, a1, a2], drive, zi)`` (its transposed direct form
    II, operation for operation) from the state of the two outputs ``out[row, :2]`` before it.
    ``drive`` is ``drives[row]``, or — with ``held`` (3,) given — the held input's drive
    ``held[0] u[k + 2] + held[1] u[k + 1] + held[2] u[k]`` of ``u = drives[row]``."""
    cdef Py_ssize_t k, n_out = out.shape[1] - 2
    cdef double y_first = out[row, 0], y_second = out[row, 1], x, y
    cdef double z0 = -a1 * y_second - a2 * y_first
    cdef double z1 = -a2 * y_second
    for k in range(n_out):
        if held.shape[0]:
            x = (
                held[0] * drives[row, k + 2] + held[1] * drives[row, k + 1] + held[2] * drives[row, k]
            )
        else:
            x = drives[row, k]
        y = z0 + b0 * x
        z0 = z1 + x * b1 - y * a1
        z1 = x * b2 - y * a2
        out[row, k + 2] = y


def second_order(
    const double[:, :] drives,
    const double[:] y_first,
    const double[:] y_second,
    double b0,
    double b1,
    double b2,
    double a1,
    double a2,
    const double[:] held=None,
):
    """``y[n+2] = -a1 y[n+1] - a2 y[n] + (b0 d[n] + b1 d[n-1] + b2 d[n-2])`` for each of S signals,
    with ``y[0], y[1]`` given (S,) each: (S, n_drives + 2), the drive ``d`` of ``drives`` (S,
    n_drives) — or, with ``held`` (3,), the drive of a first-order-hold input ``u = drives`` (S,
    n_drives + 2): ``held[0] u[n+2] + held[1] u[n+1] + held[2] u[n]``. The same numbers as SciPy's
    ``lfilter`` with its initial state set from ``y[1], y[0]`` (the filter is its loop, operation
    for operation)."""
    cdef Py_ssize_t n_signals = drives.shape[0], row
    cdef Py_ssize_t n_out = drives.shape[1] + 2 if held is None else drives.shape[1]
    if n_out < 2:
        raise ValueError(f"second_order: {n_out} samples, 2 or more wanted")
    cdef double[:, ::1] out = empty((n_signals, n_out))
    cdef const double[:] hold = empty(0) if held is None else held
    with nogil:
        for row in range(n_signals):
            out[row, 0] = y_first[row]
            out[row, 1] = y_second[row]
            _filter_row(drives, row, out, b0, b1, b2, a1, a2, hold)
    return out.base


def foh_responses(
    const double[:, :] inputs,
    const double[:] y_first,
    const double[:] z_first,
    const double[:, :] transition,
    const double[:] now,
    const double[:] after,
):
    """Exact (first-order hold) positions (S, n) of S signals driven by ``inputs`` (S, n), n >= 3, from ``y[0] = y_first`` and ``z[0] = z_first`` (S,) each (None: zeros): the second
    sample from the state's transition (2, 2) and the hold's ``now`` and ``after`` weights (2,),
    then :func:`second_order` with the held system's transfer function written out for
    ``C = [1, 0]`` — the NumPy expressions it replaced, operation for operation."""
    cdef Py_ssize_t n_signals = inputs.shape[0], n = inputs.shape[1], row, k
    if n < 3 or (y_first is not None and y_first.shape[0] != n_signals) or (
        z_first is not None and z_first.shape[0] != n_signals
    ):
        raise ValueError(
            f"foh_responses: {n} samples (3 or more wanted) and y_first, z_first of one value per signal"
        )
    cdef double p11 = transition[0, 0], p12 = transition[0, 1]
    cdef double p21 = transition[1, 0], p22 = transition[1, 1]
    cdef double a1 = -(p11 + p22)
    cdef double a2 = p11 * p22 - p12 * p21
    cdef double b0 = after[0]
    cdef double b1 = now[0] - p22 * after[0] + p12 * after[1]
    cdef double b2 = -p22 * now[0] + p12 * now[1]
    cdef double[:, ::1] out = empty((n_signals, n))
    cdef double[::1] held = empty(3)
    cdef double first, z
    held[0] = b0
    held[1] = b1
    held[2] = b2
    with nogil:
        for row in range(n_signals):
            first = 0.0 if y_first is None else y_first[row]
            z = 0.0 if z_first is None else z_first[row]
            out[row, 0] = first
            out[row, 1] = ((p11 * first + p12 * z) + now[0] * inputs[row, 0]) + after[0] * inputs[row, 1]
            _filter_row(inputs, row, out, 1.0, 0.0, 0.0, a1, a2, held)
    return out.base


def forcing_target(
    const double[:, :] y,
    const double[:] gate,
    double dt,
    double tau,
    double tau_squared,
    double alpha,
    double beta,
    double K,
):
    """The forcing term (T, D) that makes the transformation system reproduce ``y`` (T, D), with
    velocity and acceleration as NumPy's ``gradient`` (twice) and the goal gate ``gate`` (T,):
    ``(tau² ÿ - alpha (beta (g - y) - tau ẏ)) / K + gate (g - y0)``, ``g = y[-1]``, ``y0 = y[0]``,
    each element the same operations in the same order as that NumPy expression (``tau_squared``
    is Python's ``tau ** 2``, as there)."""
    cdef Py_ssize_t n = y.shape[0], n_dims = y.shape[1], i, k
    if n < 2 or gate.shape[0] != n:
        raise ValueError(f"forcing_target: {n} samples and a gate of {gate.shape[0]}")
    cdef double[::1] velocity = empty(n)
    cdef double[::1] acceleration = empty(n)
    cdef double[:, ::1] out = empty((n, n_dims))
    cdef double goal, spring, offset
    with nogil:
        for k in range(n_dims):
            _gradient(y[:, k], velocity, dt)
            _gradient(velocity, acceleration, dt)
            goal = y[n - 1, k]
            offset = goal - y[0, k]
            for i in range(n):
                spring = alpha * (beta * (goal - y[i, k]) - tau * velocity[i])
                out[i, k] = (tau_squared * acceleration[i] - spring) / K + gate[i] * offset
    return out.base


def goal_gate(const double[:] share, double dt, double alpha, double beta, double K):
    """The gate ``(alpha beta (1 - R) - R'' - alpha R') / K`` (n,) whose continuous response is the
    goal share ``R`` (n,), ``R'`` and ``R''`` as NumPy's ``gradient`` (twice), each element the
    same operations in the same order as that NumPy expression; ``alpha beta / K`` at the start."""
    cdef Py_ssize_t n = share.shape[0], i
    if n < 2:
        raise ValueError(f"goal_gate: {n} samples, 2 or more wanted")
    cdef double[::1] rate = empty(n)
    cdef double[::1] curvature = empty(n)
    cdef double[::1] gate = empty(n)
    cdef double spring = alpha * beta
    with nogil:
        _gradient(share, rate, dt)
        _gradient(rate, curvature, dt)
        for i in range(n):
            gate[i] = (spring * (1.0 - share[i]) - curvature[i] - alpha * rate[i]) / K
        gate[0] = spring / K
    return gate.base


# -- the smoothstep's blends: their arguments here, the fourth powers in NumPy, the rest here -----
# NumPy's vectorised power (SVML on AVX-512 machines) is not the C library's pow to the bit, so the
# powers u⁴ of the 7th-order smoothstep 35u⁴ - 84u⁵ + 70u⁶ - 20u⁷ stay NumPy's: a blend is two
# calls of this module around one of NumPy's.

cdef inline double _clipped(double u) noexcept nogil:
    """``np.clip(u, 0.0, 1.0)``."""
    return 0.0 if u < 0.0 else (1.0 if u > 1.0 else u)


cdef inline double _smoothstep(double u, double u4) noexcept nogil:
    """The smoothstep of a clipped ``u`` from its power ``u4`` (NumPy's ``u**4``), in the
    operations of ``u**4 * (35.0 + u * (-84.0 + u * (70.0 - 20.0 * u)))``."""
    return u4 * (35.0 + u * (-84.0 + u * (70.0 - 20.0 * u)))


def goal_share_arguments(Py_ssize_t n, double dt, double begin, double end, double width):
    """The smoothstep's arguments of the goal share on ``n`` samples ``dt`` apart (2, n), clipped to
    [0, 1]: its rise ``(s - begin) / width`` and its close ``(end - s) / width``, ``s = i dt``."""
    cdef double[:, ::1] out = empty((2, n))
    cdef Py_ssize_t i
    cdef double s
    with nogil:
        for i in range(n):
            s = i * dt
            out[0, i] = _clipped((s - begin) / width)
            out[1, i] = _clipped((end - s) / width)
    return out.base


def goal_share(
    const double[:] progress,
    const double[:, :] arguments,
    const double[:, :] powers,
    double dt,
    double end,
    double width,
):
    """The goal share (n,) from the progress (n,) and the smoothstep's ``arguments`` (2, n) of
    :func:`goal_share_arguments` with their fourth ``powers``: ``σ S(rise)``, then ``1 - (1 - σ)
    S(close)`` from ``end - width`` on, then 1 from ``end`` on."""
    cdef Py_ssize_t n = progress.shape[0], i
    if (arguments.shape[0], arguments.shape[1], powers.shape[0], powers.shape[1]) != (2, n, 2, n):
        raise ValueError(f"goal_share: arguments and powers must be (2, {n})")
    cdef double[::1] share = empty(n)
    cdef double s, closing = end - width
    with nogil:
        for i in range(n):
            s = i * dt
            if s >= end:
                share[i] = 1.0
            elif s > closing:
                share[i] = 1.0 - (1.0 - progress[i]) * _smoothstep(arguments[1, i], powers[1, i])
            else:
                share[i] = progress[i] * _smoothstep(arguments[0, i], powers[0, i])
    return share.base


def rest_blend_arguments(Py_ssize_t n, double dt, double start_width, double end_width):
    """The smoothstep's arguments of the rest blends on ``n`` samples ``dt`` apart (2, n), clipped
    to [0, 1]: ``s / start_width`` and ``(s[-1] - s) / end_width`` (0 where a width is 0: that end
    is not blended)."""
    cdef double[:, ::1] out = empty((2, n))
    cdef Py_ssize_t i
    cdef double last = (n - 1) * dt
    with nogil:
        for i in range(n):
            out[0, i] = _clipped(i * dt / start_width) if start_width != 0.0 else 0.0
            out[1, i] = _clipped((last - i * dt) / end_width) if end_width != 0.0 else 0.0
    return out.base


def rest_blended(
    const double[:, :] y,
    const double[:, :] arguments,
    const double[:, :] powers,
    double dt,
    const double[:] start_velocity,
    const double[:] end_velocity,
    double start_width,
    double end_width,
):
    """``y`` (T, D) with its start velocity blended out over ``start_width`` and its end velocity
    over ``end_width`` (normalised time; 0: not blended): ``y - v₀ s (1 - S(s / w₀))``, then
    ``+ v₁ (s_T - s) (1 - S((s_T - s) / w₁))``, from :func:`rest_blend_arguments` and their fourth
    ``powers``, in the operations of the NumPy expressions it replaced."""
    cdef Py_ssize_t n = y.shape[0], n_dims = y.shape[1], i, k
    cdef double[:, ::1] out = array(y, dtype=float, order="C", copy=True)
    cdef double last = (n - 1) * dt, elapsed, blend
    with nogil:
        if start_width != 0.0:
            for i in range(n):
                elapsed = i * dt
                blend = -1.0 * (elapsed * (1.0 - _smoothstep(arguments[0, i], powers[0, i])))
                for k in range(n_dims):
                    out[i, k] = out[i, k] + blend * start_velocity[k]
        if end_width != 0.0:
            for i in range(n):
                elapsed = last - i * dt
                blend = 1.0 * (elapsed * (1.0 - _smoothstep(arguments[1, i], powers[1, i])))
                for k in range(n_dims):
                    out[i, k] = out[i, k] + blend * end_velocity[k]
    return out.base


def stamp_verdict(const double[:] t, double min_rate, double max_rate, double max_abs):
    """What a fit makes of timestamps ``t`` (n,) in one pass: 1 if they are valid and uniform
    (their steps, from the first stamp, spread by at most 1e-9 of their mean: the samples are
    taken as they are), 2 if valid and to be resampled, 0 for anything the checked path must
    word or repair — fewer than two, NaN, inf or beyond ``max_abs``, a step that is not positive
    (a repeated stamp is dropped there), a rate outside [``min_rate``, ``max_rate``] Hz. The
    mean step is summed in order (NumPy sums pairwise): only a spread within rounding of the
    1e-9 line could be judged otherwise, and either way the samples are the same to ~1e-9."""
    cdef Py_ssize_t n = t.shape[0], i
    cdef double first, previous, value, step, low = INFINITY, high = -INFINITY, total = 0.0
    cdef double rate
    cdef bint valid = n >= 2
    with nogil:
        for i in range(n if valid else 0):
            if not fabs(t[i]) <= max_abs:  # (NaN compares false)
                valid = False
                break
        first = t[0] if valid else 0.0
        previous = 0.0
        for i in range(1, n if valid else 0):
            if not t[i] > t[i - 1]:
                valid = False
                break
            value = t[i] - first
            step = value - previous
            previous = value
            total += step
            if step < low:
                low = step
            if step > high:
                high = step
    if not valid:
        return 0
    rate = (n - 1) / (t[n - 1] - t[0])
    if not (min_rate <= rate <= max_rate):
        return 0
    return 1 if high - low <= 1e-9 * (total / (n - 1)) else 2


def interp_columns(const double[:] x_new, const double[:] x, const double[:, :] y):
    """``np.interp(x_new, x, column)`` for every column of ``y`` (n, D), as (m, D): ``x`` (n,)
    increasing and ``x_new`` (m,) non-decreasing (a resampling grid), so one merge scan finds each
    interval. NumPy's arithmetic and its special cases: NaN at a NaN, the sample's own value on a
    knot, the end values beyond the ends, ``slope (x - x[j]) + y[j]`` between (from the right end
    if that is NaN)."""
    cdef Py_ssize_t m = x_new.shape[0], n = x.shape[0], n_dims = y.shape[1], i, j = 0, k
    if n < 1 or y.shape[0] != n:
        raise ValueError(f"interp_columns: x has {n} values and y {y.shape[0]} rows")
    cdef double[:, ::1] out = empty((m, n_dims))
    cdef double value, slope, result
    with nogil:
        for i in range(m):
            value = x_new[i]
            if value != value:  # NaN in, NaN out (but a single knot's value, as NumPy has it)
                for k in range(n_dims):
                    out[i, k] = y[0, k] if n == 1 else value
                continue
            if value > x[n - 1]:
                for k in range(n_dims):
                    out[i, k] = y[n - 1, k]
                continue
            if value < x[0]:
                for k in range(n_dims):
                    out[i, k] = y[0, k]
                continue
            if value == x[n - 1]:
                for k in range(n_dims):
                    out[i, k] = y[n - 1, k]
                continue
            while j + 1 < n and x[j + 1] <= value:  # x[j] <= value < x[j + 1]
                j += 1
            while j > 0 and x[j] > value:  # (a grid that steps back: never, but stay exact)
                j -= 1
            for k in range(n_dims):
                if x[j] == value:
                    out[i, k] = y[j, k]
                    continue
                slope = (y[j + 1, k] - y[j, k]) / (x[j + 1] - x[j])
                result = slope * (value - x[j]) + y[j, k]
                if result != result:
                    result = slope * (value - x[j + 1]) + y[j + 1, k]
                    if result != result and y[j, k] == y[j + 1, k]:
                        result = y[j, k]
                out[i, k] = result
    return out.base


def exact_state(
    const double[:, :] y,
    const double[:, :] inputs,
    double transition_yy,
    double transition_yz,
    double now_y,
    double after_y,
    double alpha_beta,
    double alpha,
    double tau_squared,
):
    """``z`` and ``d²y/ds²`` (n, D) of an exact rollout from its positions and inputs (n + 1, D):
    ``z[l] = (y[l+1] - Φ₁₁ y[l] - Γ₀₁ u[l] - Γ₁₁ u[l+1]) / Φ₁₂`` and ``(u[l] - αβ y[l] - α z[l]) /
    tau²``, in the operations of the NumPy expressions it replaced (``alpha_beta`` and
    ``tau_squared`` are Python's ``alpha * beta`` and ``tau ** 2``, as there)."""
    cdef Py_ssize_t n = y.shape[0] - 1, n_dims = y.shape[1], l, k
    if n < 0 or inputs.shape[0] != n + 1 or inputs.shape[1] != n_dims:
        raise ValueError("exact_state: y and inputs must have the same shape (n + 1, D)")
    cdef double[:, ::1] z = empty((n, n_dims))
    cdef double[:, ::1] acceleration = empty((n, n_dims))
    with nogil:
        for l in range(n):
            for k in range(n_dims):
                z[l, k] = (
                    (y[l + 1, k] - transition_yy * y[l, k])
                    - now_y * inputs[l, k]
                    - after_y * inputs[l + 1, k]
                ) / transition_yz
                acceleration[l, k] = (
                    inputs[l, k] - alpha_beta * y[l, k] - alpha * z[l, k]
                ) / tau_squared
    return z.base, acceleration.base


def exact_rates(
    const double[:, :] y,
    const double[:, :] forcing,
    const double[:] gate,
    const double[:] goal,
    const double[:] start,
    const double[:] z_first,
    double K,
    double alpha_beta,
    double alpha,
    double tau_squared,
    double transition_yy,
    double transition_yz,
    double now_y,
    double after_y,
    double z_scale,
    double acceleration_scale,
):
    """Velocities and accelerations (n, D) of an exact rollout, from its positions ``y``, forcing
    term and goal gate (n + 1 rows): :func:`exact_state` on the inputs ``u = K f - gate K (g - y0)
    + αβ g``, its first state ``z_first`` (D,) given (None: at rest), ``z / z_scale`` and
    ``acceleration / acceleration_scale`` — the NumPy expressions of a timed trajectory's rates,
    operation for operation (``alpha_beta``, ``tau_squared`` and the scales Python's products)."""
    cdef Py_ssize_t n = y.shape[0] - 1, n_dims = y.shape[1], l, k
    if (
        n < 1 or forcing.shape[0] != n + 1 or forcing.shape[1] != n_dims
        or gate.shape[0] != n + 1 or goal.shape[0] != n_dims or start.shape[0] != n_dims
        or (z_first is not None and z_first.shape[0] != n_dims)
    ):
        raise ValueError(
            "exact_rates: y and forcing must be (n + 1, D), gate (n + 1,), goal, start and z_first (D,)"
        )
    cdef double[:, ::1] velocity = empty((n, n_dims))
    cdef double[:, ::1] acceleration = empty((n, n_dims))
    cdef double[::1] offset = empty(n_dims)  # K (g - y0)
    cdef double[::1] held = empty(n_dims)  # αβ g
    cdef double[::1] carried = empty(n_dims)  # each sample's input, formed once: u[l + 1] -> u[l]
    cdef double now, after, z
    cdef bint at_rest = z_first is None
    with nogil:
        for k in range(n_dims):
            offset[k] = K * (goal[k] - start[k])
            held[k] = alpha_beta * goal[k]
            carried[k] = (K * forcing[0, k] - gate[0] * offset[k]) + held[k]
        for l in range(n):
            for k in range(n_dims):
                now = carried[k]
                after = (K * forcing[l + 1, k] - gate[l + 1] * offset[k]) + held[k]
                carried[k] = after
                if l == 0:  # the first state is given, not solved for: a rest start is at rest
                    z = 0.0 if at_rest else z_first[k]
                else:
                    z = (
                        (y[l + 1, k] - transition_yy * y[l, k]) - now_y * now - after_y * after
                    ) / transition_yz
                velocity[l, k] = z / z_scale
                acceleration[l, k] = (
                    (now - alpha_beta * y[l, k] - alpha * z) / tau_squared
                ) / acceleration_scale
    return velocity.base, acceleration.base


# -- unit quaternions (x, y, z, w), in SciPy's Rotation arithmetic --------------------------------
# SciPy's Rotation costs about 0.3 ms a product on arrays (its array-API dispatch), most of a pose
# DMP's fit and trajectory. These loops are its Cython backend's operations, step by step (the
# C library's sqrt, sin, cos and atan2, as there), so a pose keeps its last bit; the tests compare
# them with Rotation on random rotations, small angles and half turns included.


cdef inline void _normalised(double* q) noexcept nogil:
    """A quaternion divided by its norm, as ``Rotation(quat, normalize=True)`` does it."""
    cdef double norm = sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3])
    q[0] = q[0] / norm
    q[1] = q[1] / norm
    q[2] = q[2] / norm
    q[3] = q[3] / norm


cdef inline void _product(const double* p, const double* q, double* r) noexcept nogil:
    """``p ⊗ q`` (Rotation's ``p * q``), in its operations: the cross product first."""
    cdef double c0 = p[1] * q[2] - p[2] * q[1]
    cdef double c1 = p[2] * q[0] - p[0] * q[2]
    cdef double c2 = p[0] * q[1] - p[1] * q[0]
    r[0] = p[3] * q[0] + q[3] * p[0] + c0
    r[1] = p[3] * q[1] + q[3] * p[1] + c1
    r[2] = p[3] * q[2] + q[3] * p[2] + c2
    r[3] = p[3] * q[3] - p[0] * q[0] - p[1] * q[1] - p[2] * q[2]


cdef inline void _goal_row(const double[:, :] goal, Py_ssize_t i, double* g) noexcept nogil:
    """Row ``i`` of ``goal`` into ``g``, normalised (``Rotation.from_quat`` of it)."""
    cdef Py_ssize_t k
    for k in range(4):
        g[k] = goal[i, k]
    _normalised(g)


cdef inline bint _flipped(const double* q) noexcept nogil:
    """Whether ``as_rotvec`` takes ``-q``: ``w < 0``, or at ``w = 0`` (a half turn) the first
    non-zero of x, y, z negative (SciPy's canonical sign)."""
    if q[3] != 0:
        return q[3] < 0
    if q[0] != 0:
        return q[0] < 0
    if q[1] != 0:
        return q[1] < 0
    return q[2] < 0


def quaternion_log(const double[:, :] q, const double[:, :] goal):
    """``(Rotation.from_quat(q) * Rotation.from_quat(goal).inv()).as_rotvec()`` (n, 3): the
    rotation vectors (rad, angle in [0, π]) from ``goal`` to each of ``q`` (n, 4); ``goal`` (1, 4)
    or (n, 4). Rows need not be of unit length (they are normalised, as Rotation does)."""
    cdef Py_ssize_t n = q.shape[0], i, k
    if q.shape[1] != 4 or goal.shape[1] != 4 or goal.shape[0] not in (1, n):
        raise ValueError("quaternion_log: q (n, 4) and goal (1, 4) or (n, 4)")
    cdef double[:, ::1] out = empty((n, 3))
    cdef double p[4]
    cdef double g[4]
    cdef double r[4]
    cdef double angle, angle2, scale
    cdef bint per_row = goal.shape[0] > 1
    with nogil:
        for i in range(n):
            for k in range(4):
                p[k] = q[i, k]
            _normalised(p)
            if i == 0 or per_row:
                _goal_row(goal, i if per_row else 0, g)
                g[0] = -g[0]  # its inverse
                g[1] = -g[1]
                g[2] = -g[2]
            _product(p, g, r)
            _normalised(r)
            if _flipped(r):  # w ≥ 0: the angle in [0, π]
                for k in range(4):
                    r[k] = -r[k]
            angle = 2 * atan2(sqrt(r[0] * r[0] + r[1] * r[1] + r[2] * r[2]), r[3])
            if angle <= 1e-3:
                angle2 = angle * angle
                scale = 2 + angle2 / 12 + 7 * angle2 * angle2 / 2880
            else:
                scale = angle / sin(angle / 2)
            out[i, 0] = scale * r[0]
            out[i, 1] = scale * r[1]
            out[i, 2] = scale * r[2]
    return out.base


def quaternion_exp(const double[:, :] error, const double[:, :] goal):
    """``(Rotation.from_rotvec(error) * Rotation.from_quat(goal)).as_quat()`` (n, 4): each rotation
    vector ``error`` (n, 3, rad) applied to ``goal`` (1, 4) or (n, 4)."""
    cdef Py_ssize_t n = error.shape[0], i, k
    if error.shape[1] != 3 or goal.shape[1] != 4 or goal.shape[0] not in (1, n):
        raise ValueError("quaternion_exp: error (n, 3) and goal (1, 4) or (n, 4)")
    cdef double[:, ::1] out = empty((n, 4))
    cdef double p[4]
    cdef double g[4]
    cdef double angle, angle2, scale
    cdef bint per_row = goal.shape[0] > 1
    with nogil:
        for i in range(n):
            angle = sqrt(
                error[i, 0] * error[i, 0] + error[i, 1] * error[i, 1] + error[i, 2] * error[i, 2]
            )
            if angle <= 1e-3:
                angle2 = angle * angle
                scale = 0.5 - angle2 / 48 + angle2 * angle2 / 3840
            else:
                scale = sin(angle / 2) / angle
            p[0] = scale * error[i, 0]
            p[1] = scale * error[i, 1]
            p[2] = scale * error[i, 2]
            p[3] = cos(angle / 2)
            if i == 0 or per_row:
                _goal_row(goal, i if per_row else 0, g)
            _product(p, g, &out[i, 0])
            _normalised(&out[i, 0])
    return out.base


def all_finite(const double[:, :] values):
    """Whether every value of ``values`` (n, D) is finite (NumPy's ``all(isfinite(values))``
    without its temporary)."""
    cdef Py_ssize_t n = values.shape[0], n_dims = values.shape[1], i, k
    cdef bint finite = True
    with nogil:
        for i in range(n):
            for k in range(n_dims):
                if not fabs(values[i, k]) <= 1.7976931348623157e308:  # NaN or inf
                    finite = False
                    break
            if not finite:
                break
    return finite


def strictly_decreasing(const double[:] values):
    """Whether each of ``values`` (n,) is below the one before (``all(diff(values) < 0)``)."""
    cdef Py_ssize_t n = values.shape[0], i
    cdef bint decreasing = True
    with nogil:
        for i in range(1, n):
            if not values[i] < values[i - 1]:
                decreasing = False
                break
    return decreasing


def extent(const double[:, :] y):
    """``(finite, low, high, motion)`` of samples ``y`` (T, D), T >= 1, in one pass: whether
    every value is finite, the smallest and largest value, and the largest distance of any
    coordinate from the first sample's (``max |y - y[0]|``; all three exact, as NumPy's min,
    max and abs are). The numbers are meaningless when ``finite`` is False."""
    cdef Py_ssize_t n = y.shape[0], n_dims = y.shape[1], i, k
    cdef double low = INFINITY, high = -INFINITY, motion = 0.0, value, offset
    cdef bint finite = True
    with nogil:
        for i in range(n):
            for k in range(n_dims):
                value = y[i, k]
                if not fabs(value) <= 1.7976931348623157e308:  # NaN or inf
                    finite = False
                    break
                if value < low:
                    low = value
                if value > high:
                    high = value
                offset = fabs(value - y[0, k])
                if offset > motion:
                    motion = offset
            if not finite:
                break
    return finite, low, high, motion


def arclength(const double[:, :] y):
    """Cumulative arc length (T,) of a path ``y`` (T, D), from 0: NumPy's
    ``concatenate([[0], cumsum(norm(diff(y, axis=0), axis=1))])`` in one pass, each step's norm the
    square root of its squares summed in order, as NumPy's reduction over three columns sums them."""
    cdef Py_ssize_t n = y.shape[0], n_dims = y.shape[1], i, k
    cdef double[::1] out = empty(max(n, 1))
    cdef double squares, step, total = 0.0
    with nogil:
        out[0] = 0.0
        for i in range(1, n):
            squares = 0.0
            for k in range(n_dims):
                step = y[i, k] - y[i - 1, k]
                squares = squares + step * step
            total = total + sqrt(squares)
            out[i] = total
    return out.base


def motion_peaks(const double[:, :] points, double dt):
    """Peak speed, acceleration and jerk (3,) of samples ``points`` (n, D) ``dt`` apart: NumPy's
    ``max(norm(diff(points, k) / dt^k, axis=1))`` for k = 1, 2, 3, each difference divided by
    ``dt`` as it is taken and each norm the square root of its squares summed in order (as NumPy
    sums fewer than eight columns); 0 for an order the samples are too few for. ``D`` < 8."""
    cdef Py_ssize_t n = points.shape[0], n_dims = points.shape[1], order, i, k
    cdef double[:, ::1] work = empty((max(n, 1), max(n_dims, 1)))
    cdef double[::1] out = empty(3)
    cdef double total, change, peak
    with nogil:
        for i in range(n):
            for k in range(n_dims):
                work[i, k] = points[i, k]
        for order in range(3):
            peak = 0.0
            for i in range(n - 1 - order):  # in place: row i + 1 is still the lower order's
                total = 0.0
                for k in range(n_dims):
                    change = (work[i + 1, k] - work[i, k]) / dt
                    work[i, k] = change
                    total = total + change * change
                total = sqrt(total)
                if total > peak or total != total:
                    peak = total
            out[order] = peak
    return out.base



def band_of(const double[:, ::1] rows, double share):
    """Where each row of ``rows`` (n, N) matters: ``(first (n,), last (n,))``, the first and last
    column whose magnitude exceeds ``share`` times the row's largest (column 0 for a row of
    zeros); a NaN always matters."""
    cdef Py_ssize_t n = rows.shape[0], n_columns = rows.shape[1], i, j
    cdef long long[::1] first = empty(n, dtype="int64")
    cdef long long[::1] last = empty(n, dtype="int64")
    cdef double bound, size
    cdef double peaks[4]
    with nogil:
        for i in range(n):
            # four running peaks: one chain of comparisons would wait on each one's latency
            peaks[0] = peaks[1] = peaks[2] = peaks[3] = 0.0
            for j in range(n_columns):
                size = fabs(rows[i, j])
                peaks[j & 3] = size if size > peaks[j & 3] else peaks[j & 3]
            bound = share * max(max(peaks[0], peaks[1]), max(peaks[2], peaks[3]))
            first[i] = 0
            last[i] = 0
            for j in range(n_columns):
                if not fabs(rows[i, j]) <= bound:
                    first[i] = j
                    break
            for j in range(n_columns - 1, -1, -1):
                if not fabs(rows[i, j]) <= bound:
                    last[i] = j
                    break
    return first.base, last.base


def band_product(const double[:, ::1] values, const long long[::1] first, const double[:, ::1] weights):
    """``rows @ weights`` (n, D) for basis rows stored as a band: row ``i``'s nonzero columns are
    ``first[i] … first[i] + w - 1``, their values ``values[i]`` (n, w); ``weights`` (N, D). Each
    output the band's products summed in column order."""
    cdef Py_ssize_t n = values.shape[0], width = values.shape[1], n_dims = weights.shape[1]
    cdef Py_ssize_t i, j, k, start
    cdef double[:, ::1] out = empty((n, n_dims))
    cdef double total
    with nogil:
        for i in range(n):
            start = first[i]
            for k in range(n_dims):
                total = 0.0
                for j in range(width):
                    total = total + values[i, j] * weights[start + j, k]
                out[i, k] = total
    return out.base


def band_transposed_product(
    const double[:, ::1] values, const long long[::1] first, const double[:, ::1] target, Py_ssize_t n_columns
):
    """``rowsᵀ @ target`` (N, D) for basis rows stored as a band (:func:`band_product`), ``target``
    (n, D), ``N = n_columns``."""
    cdef Py_ssize_t n = values.shape[0], width = values.shape[1], n_dims = target.shape[1]
    cdef Py_ssize_t i, j, k, column
    cdef double[:, ::1] out = empty((n_columns, n_dims))
    cdef double value
    with nogil:
        for column in range(n_columns):
            for k in range(n_dims):
                out[column, k] = 0.0
        for i in range(n):
            for j in range(width):
                value = values[i, j]
                column = first[i] + j
                for k in range(n_dims):
                    out[column, k] = out[column, k] + value * target[i, k]
    return out.base
