#!/usr/bin/env python3
"""Independent reference for the geofence accuracy table (services/protocol/tests/geofence_accuracy.rs).

Computes, with GeographicLib (Karney's official Python package) and the standard library only,
the signed margin of a path (a point, a track-to-fix leg or a radius-to-fix arc) against one
zone (a no-fly-zone polygon or circle, or a fly-zone polygon), in geodesic metres on WGS-84,
before any safety offset. The output is a CSV that the geofence module's test reads; the module
must agree within 0.5 m on every row. Nothing here shares code with the module under test.

Geometry (ICD §4, #2012 "Geometry"):
- a polygon edge and a leg are the geodesics between their end points; polygons are listed in
  order, not closed (the last vertex connects to the first);
- a circle is the set of points within its radius (geodesic distance) of its centre;
- a radius-to-fix arc is the point at azimuth theta from the centre at geodesic distance
  r(theta), theta sweeping from azimuth(centre->start) to azimuth(centre->end) in the turn
  direction (cw: azimuth increasing, ccw: decreasing; sweep in [0, 360)), r going linearly with
  the swept fraction from dist(centre, start) to dist(centre, end).

- a fly-by turn (ARINC 424 fly-by, what guidance flies at a fly-by waypoint W between the
  track-to-fix legs A->W and W->B at turn radius r) is the arc of the geodesic circle of radius r
  tangent to both geodesics, inside the corner: its centre C is the point at geodesic distance r
  from both geodesics (through A, W and through W, B, extended) on the side of the turn, found
  here by Newton's method on those two exact distances (each the minimum over the position along
  the geodesic); the arc runs from the foot of C on A->W to the foot of C on W->B in the turn
  direction, at radius r (the arc of the form above with r_start = r_end = r).

Margin of a path against a zone:
- border distance of P: polygon: min over edges of the geodesic distance from P to the geodesic
  segment (minimised over the position along the edge); circle: |dist(centre, P) - r|;
- forbidden side: inside for a no-fly-zone, outside for a fly-zone. Polygon inside test: winding
  number of the geodesic azimuths from P to the vertices (no projection); circle: dist < r;
- f(P) = +border distance on the allowed side, -border distance on the forbidden side. f is
  continuous (0 on the border), and min over the path of f is exactly the margin of the brief:
  + the smallest border distance when the path never reaches the forbidden side, else - the
  largest depth on the forbidden side. at_lat/at_lon is where that minimum is reached.

Minimisation (both over the path parameter and over the position along an edge): coarse
sampling (end points included, so a minimum at an end is exact), then golden-section refinement
around the best coarse local minima until the bracket is shorter than 1 mm along the curve.
An edge whose coarse minimum minus half its sample spacing cannot beat the best distance found
so far is not refined: by the triangle inequality its true minimum cannot be smaller.

Usage:
    python3 services/protocol/tests/data/geofence_reference.py > services/protocol/tests/data/geofence_accuracy.csv
    python3 services/protocol/tests/data/geofence_reference.py --check   # finer settings, report differences

Deterministic: no randomness, no clocks in the output, single process.
"""

import math
import sys
import time

import geographiclib
from geographiclib.geodesic import Geodesic

G = Geodesic.WGS84
DIST = Geodesic.DISTANCE
AZI = Geodesic.AZIMUTH
LATLON = Geodesic.LATITUDE | Geodesic.LONGITUDE
# Capabilities of a GeodesicLine that is asked for positions by distance along it.
LINE_CAPS = Geodesic.STANDARD | Geodesic.DISTANCE_IN
INVPHI = (math.sqrt(5.0) - 1.0) / 2.0


class Settings:
    """Sampling and stopping rules of the minimisations."""

    def __init__(self, path_samples, edge_samples, tol_m, refine_minima):
        self.path_samples = path_samples  # coarse samples along the path (ends included)
        self.edge_samples = edge_samples  # coarse samples along each polygon edge
        self.tol_m = tol_m  # golden-section stops when the bracket is shorter than this
        self.refine_minima = refine_minima  # coarse local minima of the path refined


NORMAL = Settings(path_samples=400, edge_samples=64, tol_m=1e-3, refine_minima=3)
FINE = Settings(path_samples=1000, edge_samples=160, tol_m=1e-5, refine_minima=5)


# ---------------------------------------------------------------------------------------------
# Small geodesic helpers


def inverse_dist(lat1, lon1, lat2, lon2):
    return G.Inverse(lat1, lon1, lat2, lon2, DIST)["s12"]


def inverse_azi(lat1, lon1, lat2, lon2):
    return G.Inverse(lat1, lon1, lat2, lon2, AZI)["azi1"]


def direct(p, azi, s):
    r = G.Direct(p[0], p[1], azi, s, LATLON)
    return (r["lat2"], r["lon2"])


def wrap180(x):
    """Wrap an angle in degrees to (-180, 180]."""
    x = math.fmod(x, 360.0)
    if x <= -180.0:
        x += 360.0
    elif x > 180.0:
        x -= 360.0
    return x


def golden_min(f, a, b, tol):
    """Minimise f on [a, b] by golden-section search until b - a < tol. Returns (x, f(x))."""
    c = b - INVPHI * (b - a)
    d = a + INVPHI * (b - a)
    fc, fd = f(c), f(d)
    while b - a > tol:
        if fc <= fd:
            b, d, fd = d, c, fc
            c = b - INVPHI * (b - a)
            fc = f(c)
        else:
            a, c, fc = c, d, fd
            d = a + INVPHI * (b - a)
            fd = f(d)
    return (c, fc) if fc <= fd else (d, fd)


def sample_params(n):
    """n parameters from 0 to 1 inclusive, evenly spaced."""
    return [i / (n - 1) for i in range(n)]


# ---------------------------------------------------------------------------------------------
# Zones


class PolygonZone:
    def __init__(self, kind, vertices, settings):
        self.kind = kind  # "nfz" or "fz"
        self.vertices = vertices
        self.settings = settings
        self.edges = []
        n = len(vertices)
        for i in range(n):
            a, b = vertices[i], vertices[(i + 1) % n]
            line = G.InverseLine(a[0], a[1], b[0], b[1], LINE_CAPS)
            length = line.s13
            params = sample_params(settings.edge_samples)
            samples = []
            for u in params:
                if u == 0.0:
                    samples.append(a)
                elif u == 1.0:
                    samples.append(b)
                else:
                    pos = line.Position(u * length, LATLON)
                    samples.append((pos["lat2"], pos["lon2"]))
            self.edges.append((line, length, params, samples))

    def inside(self, p):
        """Winding number of the geodesic azimuths from p to the vertices."""
        azis = [inverse_azi(p[0], p[1], v[0], v[1]) for v in self.vertices]
        total = 0.0
        for i in range(len(azis)):
            total += wrap180(azis[(i + 1) % len(azis)] - azis[i])
        return abs(total) > 180.0

    def border_distance(self, p):
        coarse = []
        for edge in self.edges:
            line, length, params, samples = edge
            dists = [inverse_dist(p[0], p[1], q[0], q[1]) for q in samples]
            k = min(range(len(dists)), key=dists.__getitem__)
            coarse.append((dists[k], k, dists, edge))
        coarse.sort(key=lambda c: c[0])
        best = coarse[0][0]
        for dmin, k, dists, edge in coarse:
            line, length, params, samples = edge
            half_spacing = length / (len(params) - 1) / 2.0
            if dmin - half_spacing >= best:
                continue  # cannot hold anything closer than `best` (triangle inequality)
            lo = params[max(k - 1, 0)]
            hi = params[min(k + 1, len(params) - 1)]

            def along(u, line=line, length=length):
                pos = line.Position(u * length, LATLON)
                return inverse_dist(p[0], p[1], pos["lat2"], pos["lon2"])

            _, d = golden_min(along, lo, hi, self.settings.tol_m / length)
            best = min(best, d, dmin)
        return best

    def signed(self, p):
        d = self.border_distance(p)
        forbidden = self.inside(p) if self.kind == "nfz" else not self.inside(p)
        return -d if forbidden else d


class CircleZone:
    def __init__(self, kind, centre, radius):
        self.kind = kind
        self.centre = centre
        self.radius = radius

    def signed(self, p):
        d = inverse_dist(self.centre[0], self.centre[1], p[0], p[1]) - self.radius
        # d < 0 inside; a no-fly-zone forbids the inside
        return d if self.kind == "nfz" else -d


# ---------------------------------------------------------------------------------------------
# Paths: position as a function of a parameter t in [0, 1]


class PointPath:
    length = 0.0

    def __init__(self, p):
        self.p = p

    def at(self, t):
        return self.p


class LegPath:
    def __init__(self, a, b):
        self.a, self.b = a, b
        self.line = G.InverseLine(a[0], a[1], b[0], b[1], LINE_CAPS)
        self.length = self.line.s13

    def at(self, t):
        if t == 0.0:
            return self.a
        if t == 1.0:
            return self.b
        pos = self.line.Position(t * self.length, LATLON)
        return (pos["lat2"], pos["lon2"])


class ArcPath:
    def __init__(self, centre, start, end, direction):
        self.centre, self.start, self.end = centre, start, end
        s = G.Inverse(centre[0], centre[1], start[0], start[1], DIST | AZI)
        e = G.Inverse(centre[0], centre[1], end[0], end[1], DIST | AZI)
        self.az0, self.r0 = s["azi1"], s["s12"]
        self.r1 = e["s12"]
        if direction == "cw":
            self.sign, self.sweep = 1.0, math.fmod(e["azi1"] - s["azi1"] + 720.0, 360.0)
        else:
            self.sign, self.sweep = -1.0, math.fmod(s["azi1"] - e["azi1"] + 720.0, 360.0)
        # Scale for the stopping rule only: an upper bound of the arc length.
        self.length = math.radians(self.sweep) * max(self.r0, self.r1) + abs(self.r1 - self.r0)

    def at(self, t):
        if t == 0.0:
            return self.start
        if t == 1.0:
            return self.end
        theta = self.az0 + self.sign * t * self.sweep
        r = self.r0 + t * (self.r1 - self.r0)
        return direct(self.centre, theta, r)


def geodesic_foot(p, a, b, guess_s):
    """Position along the geodesic through a and b (distance from a, possibly beyond b or
    before a) closest to p, and that distance: golden section on the exact distance about
    guess_s."""
    line = G.InverseLine(a[0], a[1], b[0], b[1], LINE_CAPS)

    def dist(s):
        pos = line.Position(s, LATLON)
        return inverse_dist(p[0], p[1], pos["lat2"], pos["lon2"])

    d0 = inverse_dist(p[0], p[1], a[0], a[1])
    span = 2.0 * d0 + 10.0
    s, d = golden_min(dist, guess_s - span, guess_s + span, 1e-7)
    pos = line.Position(s, LATLON)
    return s, d, (pos["lat2"], pos["lon2"])


def flyby_arc(a, w, b, r):
    """The fly-by arc at w between the geodesics a->w and w->b at radius r (see the module
    documentation): centre, start, end, direction."""
    g_in = G.Inverse(a[0], a[1], w[0], w[1], DIST | AZI)
    g_out = G.Inverse(w[0], w[1], b[0], b[1], DIST | AZI)
    course_in, course_out = g_in["azi2"], g_out["azi1"]
    delta = wrap180(course_out - course_in)
    side = 1.0 if delta > 0.0 else -1.0
    length_in = g_in["s12"]

    def residual(beta, rho):
        c = direct(w, beta, rho)
        _, d1, _ = geodesic_foot(c, a, w, length_in)
        _, d2, _ = geodesic_foot(c, w, b, 0.0)
        return (d1 - r, d2 - r)

    # Start from the flat answer: on the bisector, r / cos(delta / 2) from w.
    beta = course_in + side * (90.0 + abs(delta) / 2.0)
    rho = r / math.cos(math.radians(abs(delta) / 2.0))
    for _ in range(30):
        f = residual(beta, rho)
        if max(abs(f[0]), abs(f[1])) < 1e-6:
            break
        hb, hr = 1e-7, 1e-4
        fb = residual(beta + hb, rho)
        fr = residual(beta, rho + hr)
        j = ((fb[0] - f[0]) / hb, (fr[0] - f[0]) / hr), ((fb[1] - f[1]) / hb, (fr[1] - f[1]) / hr)
        det = j[0][0] * j[1][1] - j[0][1] * j[1][0]
        beta -= (f[0] * j[1][1] - f[1] * j[0][1]) / det
        rho -= (j[0][0] * f[1] - j[1][0] * f[0]) / det
    else:
        raise ValueError("fly-by centre did not converge")
    c = direct(w, beta, rho)
    _, _, t1 = geodesic_foot(c, a, w, length_in)
    _, _, t2 = geodesic_foot(c, w, b, 0.0)
    return c, t1, t2, "cw" if side > 0.0 else "ccw"


def path_margin(path, zone, settings):
    """min over the path of zone.signed, and the parameter where it is reached."""
    if isinstance(path, PointPath):
        return zone.signed(path.p), 0.0
    params = sample_params(settings.path_samples)
    values = [zone.signed(path.at(t)) for t in params]
    n = len(values)
    minima = [
        i
        for i in range(n)
        if (i == 0 or values[i] <= values[i - 1]) and (i == n - 1 or values[i] <= values[i + 1])
    ]
    minima.sort(key=values.__getitem__)
    best_t, best = params[minima[0]], values[minima[0]]
    for i in minima[: settings.refine_minima]:
        lo, hi = params[max(i - 1, 0)], params[min(i + 1, n - 1)]
        t, v = golden_min(lambda t: zone.signed(path.at(t)), lo, hi, settings.tol_m / path.length)
        if v < best:
            best_t, best = t, v
    return best, best_t


def flat_stretch(path, zone, t, margin, within=1e-3):
    """Length (m, approximate for arcs) of the stretch of path around t where the signed
    border distance stays within `within` of the margin: how well at_lat/at_lon is determined
    (a diagnostic for stderr only)."""
    if isinstance(path, PointPath):
        return 0.0

    def flat(u):
        return zone.signed(path.at(u)) <= margin + within

    ends = []
    for end in (0.0, 1.0):
        if flat(end):
            ends.append(end)
            continue
        inner, outer = t, end
        while abs(outer - inner) * path.length > 1e-3:
            mid = (inner + outer) / 2.0
            if flat(mid):
                inner = mid
            else:
                outer = mid
        ends.append(inner)
    return (ends[1] - ends[0]) * path.length


# ---------------------------------------------------------------------------------------------
# Text form (what the CSV holds; the computation reads its own text back, so it uses exactly
# the rounded coordinates the test sees)


def fmt_deg(x):
    s = "%.7f" % x
    return "0.0000000" if s == "-0.0000000" else s


def norm_lon(lon):
    lon = wrap180(lon)
    return -180.0 if lon == 180.0 else lon


def fmt_pos(p):
    return "%s %s" % (fmt_deg(p[0]), fmt_deg(norm_lon(p[1])))


def parse_pos(s):
    lat, lon = s.split()
    return (float(lat), float(lon))


def path_text(kind, points, direction=None):
    body = ";".join(fmt_pos(p) for p in points)
    if kind == "arc":
        body += ";" + direction
    if kind == "flyby":
        body += ";%.3f" % direction  # the turn radius
    if kind == "flyby-wind":
        body += ";%.1f %.1f;%.1f" % direction  # airspeed, wind speed; bank
    return "%s:%s" % (kind, body)


def zone_text(kind, shape, data):
    if shape == "polygon":
        return "%s-polygon:%s" % (kind, ";".join(fmt_pos(v) for v in data))
    centre, radius = data
    return "%s-circle:%s;%.3f" % (kind, fmt_pos(centre), radius)


def parse_path(text):
    kind, body = text.split(":", 1)
    parts = body.split(";")
    if kind == "point":
        return PointPath(parse_pos(parts[0]))
    if kind == "leg":
        return LegPath(parse_pos(parts[0]), parse_pos(parts[1]))
    if kind == "arc":
        return ArcPath(parse_pos(parts[0]), parse_pos(parts[1]), parse_pos(parts[2]), parts[3])
    if kind == "flyby":
        a, w, b = (parse_pos(x) for x in parts[:3])
        return ArcPath(*flyby_arc(a, w, b, float(parts[3])))
    if kind == "flyby-wind":
        a, w, b = (parse_pos(x) for x in parts[:3])
        v, wind = (float(x) for x in parts[3].split())
        return ArcPath(*flyby_arc(a, w, b, wind_radius(v, wind, float(parts[4]))))
    raise ValueError(text)


def wind_radius(v, wind, bank):
    """The turn radius in wind (ICD §7 "Turns in wind"): (v + W)^2 / (g tan(bank)), metres."""
    return (v + wind) ** 2 / (9.80665 * math.tan(math.radians(bank)))


def parse_zone(text, settings):
    head, body = text.split(":", 1)
    kind, shape = head.split("-")
    parts = body.split(";")
    if shape == "polygon":
        return PolygonZone(kind, [parse_pos(s) for s in parts], settings)
    return CircleZone(kind, parse_pos(parts[0]), float(parts[1]))


# ---------------------------------------------------------------------------------------------
# Construction helpers for the rows (they only place the geometry; the margins are computed
# from the rounded text afterwards)


def on_leg(a, b, frac):
    """Point at fraction frac of the geodesic a->b, and the forward azimuth there."""
    line = G.InverseLine(a[0], a[1], b[0], b[1], LINE_CAPS)
    pos = line.Position(frac * line.s13, LATLON | AZI)
    return (pos["lat2"], pos["lon2"]), pos["azi2"]


def local(origin, azi, along, right):
    """Move `along` metres on azimuth azi, then `right` metres to the right of the track."""
    r = G.Direct(origin[0], origin[1], azi, along, LATLON | AZI)
    return direct((r["lat2"], r["lon2"]), r["azi2"] + 90.0, right)


def polygon_local(origin, azi, offsets):
    """Polygon from (along, right) offsets in metres in the track frame at origin."""
    return [local(origin, azi, a, r) for a, r in offsets]


def polygon_polar(centre, spokes):
    """Polygon from (azimuth, distance) spokes around a centre."""
    return [direct(centre, az, d) for az, d in spokes]


def geodesic_apex(a, b):
    """Point of largest |latitude| on the geodesic a->b (by sampling and golden section)."""
    line = G.InverseLine(a[0], a[1], b[0], b[1], LINE_CAPS)
    sgn = 1.0 if a[0] + b[0] >= 0 else -1.0

    def neg_lat(s):
        return -sgn * line.Position(s, LATLON)["lat2"]

    n = 200
    k = min(range(n + 1), key=lambda i: neg_lat(i * line.s13 / n))
    s, _ = golden_min(neg_lat, max(k - 1, 0) * line.s13 / n, min(k + 1, n) * line.s13 / n, 1e-4)
    pos = line.Position(s, LATLON)
    return (pos["lat2"], pos["lon2"])


def arc_text(centre, az0, r0, az1, r1, direction):
    return path_text("arc", [centre, direct(centre, az0, r0), direct(centre, az1, r1)], direction)


def leg_text(a, b):
    return path_text("leg", [a, b])


def point_text(p):
    return path_text("point", [p])


def rows():
    """(name, path text, zone text) of every row, in table order."""
    out = []

    def add(name, path, zone):
        out.append((name, path, zone))

    # --- legs of about 100 km ----------------------------------------------------------------
    # Mid-latitude (Bavaria to Bohemia), 100 km NE; a no-fly-zone beside the track, clear.
    a, b = (48.40, 11.80), direct((48.40, 11.80), 60.0, 100_000.0)
    q, az = on_leg(a, b, 0.55)
    add("leg_100km_midlat_nfz_clear",
        leg_text(a, b),
        zone_text("nfz", "polygon", polygon_local(q, az, [
            (-2500, 640), (1800, 700), (3200, 2600), (400, 4100), (-3000, 2900)])))
    # Same leg; a pentagon whose corner pokes 250 m across the track.
    q, az = on_leg(a, b, 0.30)
    add("leg_100km_midlat_nfz_entered",
        leg_text(a, b),
        zone_text("nfz", "polygon", polygon_local(q, az, [
            (0, 250), (2200, -1500), (4800, -1900), (5200, -4200), (900, -4600)])))
    # 65 N (Finland), 100 km NNE; a heptagon whose nearest vertex is 80 m from the track.
    a, b = (64.90, 25.40), direct((64.90, 25.40), 20.0, 100_000.0)
    q, az = on_leg(a, b, 0.62)
    add("leg_100km_lat65_nfz_near",
        leg_text(a, b),
        zone_text("nfz", "polygon", polygon_local(q, az, [
            (-1500, -130), (0, -80), (1500, -150), (2600, -900), (1700, -2300),
            (-1200, -2500), (-2400, -1100)])))
    # 80 N (Svalbard), 100 km due east in lat/lon: the geodesic bulges about 1 km north of the
    # parallel. A no-fly-zone north of the parallel, its southern vertex 300 m south of the
    # geodesic's apex, that only the geodesic enters. (A vertex, not an edge along the track,
    # so that the deepest point is one well-defined place.)
    a, b = (80.00, 15.00), (80.00, 15.00 + 100_000.0 / (111_700.0 * math.cos(math.radians(80))))
    apex = geodesic_apex(a, b)
    add("leg_100km_lat80_nfz_entered",
        leg_text(a, b),
        zone_text("nfz", "polygon", [
            direct(apex, 0.0, -300.0), (apex[0] + 0.010, apex[1] + 0.15),
            (apex[0] + 0.040, apex[1] + 0.12), (apex[0] + 0.045, apex[1] - 0.10),
            (apex[0] + 0.010, apex[1] - 0.15)]))
    # 79-80 N, 100 km roughly north-west; a triangle 1.5 km off to the left.
    a, b = (79.20, 20.50), direct((79.20, 20.50), 330.0, 100_000.0)
    q, az = on_leg(a, b, 0.45)
    add("leg_100km_lat80_nfz_clear",
        leg_text(a, b),
        zone_text("nfz", "polygon", polygon_local(q, az, [
            (-3000, -1800), (2500, -1500), (0, -6000)])))
    # Southern hemisphere (New South Wales), 100 km WSW; a quadrilateral 45 m to the left.
    a, b = (-33.95, 151.10), direct((-33.95, 151.10), 250.0, 100_000.0)
    q, az = on_leg(a, b, 0.40)
    add("leg_100km_south_nfz_near",
        leg_text(a, b),
        zone_text("nfz", "polygon", polygon_local(q, az, [
            (-1800, -120), (0, -45), (2100, -160), (900, -2900), (-1500, -2400)])))

    # --- the case that first showed it: 35 km east-west at 71 N -----------------------------------
    # The geodesic runs about 70 m north of the straight lat/lon line at the midpoint. Zone 1's
    # southern vertex is 40 m south of the geodesic (30 m north of the straight line): entered.
    # Zone 2's southern vertex is 40 m north of the geodesic: missed.
    a, b = (71.00, 25.00), (71.00, 25.00 + 35_000.0 / (111_600.0 * math.cos(math.radians(71))))
    apex = geodesic_apex(a, b)
    for name, offset in (("leg_35km_lat71_nfz_entered", -40.0), ("leg_35km_lat71_nfz_missed", 40.0)):
        add(name,
            leg_text(a, b),
            zone_text("nfz", "polygon", [
                direct(apex, 0.0, offset), (apex[0] + 0.0008, apex[1] + 0.03),
                (apex[0] + 0.012, apex[1] + 0.025), (apex[0] + 0.010, apex[1] - 0.028),
                (apex[0] + 0.0008, apex[1] - 0.03)]))

    # --- across the antimeridian ----------------------------------------------------------------
    # Chukotka, 65 N: leg from 179.8 E to 179.7 W against a polygon straddling 180, entered.
    a, b = (65.00, 179.80), (65.05, -179.70)
    add("leg_antimeridian_nfz_entered",
        leg_text(a, b),
        zone_text("nfz", "polygon", [
            (65.017, 179.930), (65.022, -179.950), (65.060, -179.920), (65.070, 179.960)]))
    # Fiji, 17 S: the same kind of leg, a straddling pentagon that it passes south of.
    a, b = (-16.80, 179.80), (-16.60, -179.70)
    q, az = on_leg(a, b, 0.5)
    add("leg_antimeridian_south_nfz_clear",
        leg_text(a, b),
        zone_text("nfz", "polygon", polygon_local(q, az, [
            (-4000, -320), (3500, -300), (5000, -2800), (0, -4500), (-4500, -2600)])))

    # --- radius-to-fix arcs ---------------------------------------------------------------------
    munich = (48.27, 11.66)
    # cw quarter turn of 1 km around a point near the Munich demo area; a hexagon outside it.
    c = direct(munich, 200.0, 1500.0)
    add("arc_cw_90_munich_nfz_polygon",
        arc_text(c, 10.0, 1000.0, 100.0, 1000.0, "cw"),
        zone_text("nfz", "polygon", polygon_polar(c, [
            (40.0, 1060.0), (55.0, 1400.0), (75.0, 1700.0), (95.0, 1500.0), (80.0, 1120.0),
            (60.0, 1050.0)])))
    # ccw 200 deg turn of 2.5 km; a 400 m no-fly circle whose centre is 2.78 km out: entered.
    c = direct(munich, 90.0, 3000.0)
    add("arc_ccw_200_munich_nfz_circle_entered",
        arc_text(c, 150.0, 2500.0, 310.0, 2500.0, "ccw"),
        zone_text("nfz", "circle", (direct(c, 20.0, 2780.0), 400.0)))
    # cw 270 deg with the radius growing from 800 m to 1200 m; a pentagon beside the end.
    c = direct(munich, 0.0, 2500.0)
    add("arc_cw_270_growing_radius_nfz_polygon",
        arc_text(c, 300.0, 800.0, 210.0, 1200.0, "cw"),
        zone_text("nfz", "polygon", polygon_polar(c, [
            (230.0, 1150.0), (240.0, 1500.0), (215.0, 1900.0), (195.0, 1600.0),
            (205.0, 1250.0)])))
    # ccw 45 deg turn of 300 m; a 120 m circle 20 m off the arc.
    c = direct(munich, 315.0, 4000.0)
    add("arc_ccw_45_small_radius_nfz_circle_clear",
        arc_text(c, 80.0, 300.0, 35.0, 300.0, "ccw"),
        zone_text("nfz", "circle", (direct(c, 57.5, 440.0), 120.0)))
    # 70 N (Tromso): cw 135 deg of 3 km; a quadrilateral that the arc cuts through.
    c = (69.65, 18.95)
    add("arc_cw_135_lat70_nfz_polygon_entered",
        arc_text(c, 200.0, 3000.0, 335.0, 3000.0, "cw"),
        zone_text("nfz", "polygon", polygon_polar(c, [
            (260.0, 2700.0), (280.0, 2650.0), (285.0, 3600.0), (255.0, 3700.0)])))
    # Southern hemisphere (Cape Town): cw sweep through north (300 -> 60 deg), radius shrinking
    # from 1.5 km to 1.2 km; a 2 km no-fly circle beyond the top.
    c = (-33.95, 18.60)
    add("arc_cw_120_through_north_south_nfz_circle",
        arc_text(c, 300.0, 1500.0, 60.0, 1200.0, "cw"),
        zone_text("nfz", "circle", (direct(c, 10.0, 3600.0), 2000.0)))
    # ccw 180 deg of 600 m turning inside a hexagonal no-fly-zone corner, shallow entry.
    c = direct(munich, 135.0, 6000.0)
    add("arc_ccw_180_munich_nfz_polygon_grazing",
        arc_text(c, 0.0, 600.0, 180.0, 600.0, "ccw"),
        zone_text("nfz", "polygon", polygon_polar(c, [
            (250.0, 590.0), (290.0, 700.0), (285.0, 1400.0), (270.0, 1700.0),
            (245.0, 1300.0), (240.0, 800.0)])))

    # --- fly-by turns (the arc tangent to both legs) -----------------------------------------------
    # A fly-by waypoint W between legs of `length` m turning `turn` degrees (positive: right) at
    # radius r; a no-fly circle of 40 m radius whose centre lies `depth` m from the arc's centre
    # on the arc's middle radial (r - 30: the arc enters it by 10 m; r + 55: 15 m clear of it,
    # between the arc and W), or a small quadrilateral inside the arc 20 m clear of it. `path`:
    # how the row names the turn (kind, data), by default by that radius.
    def flyby(name, w, course_in, turn, r, length, zone, path=None):
        a = direct(w, course_in + 180.0, length)
        g = G.Inverse(a[0], a[1], w[0], w[1], AZI)
        b = direct(w, g["azi2"] + turn, length)
        c, t1, t2, direction = flyby_arc(a, w, b, r)
        az1 = inverse_azi(c[0], c[1], t1[0], t1[1])
        az2 = inverse_azi(c[0], c[1], t2[0], t2[1])
        mid = az1 + wrap180(az2 - az1) / 2.0
        if zone == "entered":
            z = zone_text("nfz", "circle", (direct(c, mid, r - 30.0), 40.0))
        elif zone == "clear":
            z = zone_text("nfz", "circle", (direct(c, mid, r + 55.0), 40.0))
        else:  # a quadrilateral inside the arc, its nearest corner 20 m from it
            z = zone_text("nfz", "polygon", polygon_polar(c, [
                (mid, r - 20.0), (mid + 25.0, r - 90.0), (mid, r - 160.0), (mid - 25.0, r - 90.0)]))
        kind, data = path or ("flyby", r)
        add(name, path_text(kind, [a, w, b], data), z)

    flyby("flyby_90_r137_munich_nfz_circle_entered", (48.27, 11.66), 0.0, 90.0, 136.7, 1500.0,
          "entered")
    flyby("flyby_30_r137_equator_nfz_circle_clear", (0.30, 32.50), 75.0, 30.0, 136.7, 1500.0,
          "clear")
    flyby("flyby_150_left_r137_lat65_nfz_polygon", (64.90, 25.40), 20.0, -150.0, 136.7, 2000.0,
          "polygon")
    flyby("flyby_120_r1000_lat80_nfz_circle_entered", (79.90, 16.00), 100.0, 120.0, 1000.0,
          6000.0, "entered")
    flyby("flyby_60_left_r500_south_nfz_polygon", (-33.95, 151.10), 250.0, -60.0, 500.0, 3000.0,
          "polygon")
    flyby("flyby_90_r5000_lat70_nfz_circle_clear", (69.65, 18.95), 300.0, 90.0, 5000.0, 20000.0,
          "clear")

    # --- fly-by turns in wind (ICD §7 "Turns in wind") -------------------------------------------
    # As above, at the radius a bank-limited aircraft holds over the ground in a wind of W from
    # any direction, (v + W)^2 / (g tan(bank)), which the reference computes itself.
    def flyby_wind(name, w, course_in, turn, v, wind, bank, length, zone):
        flyby(name, w, course_in, turn, wind_radius(v, wind, bank), length, zone,
              path=("flyby-wind", (v, wind, bank)))

    flyby_wind("flyby_wind_90_v25_w12_munich_nfz_circle_entered", (48.27, 11.66), 0.0, 90.0,
               25.0, 12.0, 25.0, 2000.0, "entered")
    flyby_wind("flyby_wind_120_left_v20_w10_equator_nfz_circle_clear", (0.30, 32.50), 75.0,
               -120.0, 20.0, 10.0, 25.0, 3000.0, "clear")
    flyby_wind("flyby_wind_60_v30_w6_lat70_nfz_circle_entered", (69.65, 18.95), 300.0, 60.0,
               30.0, 6.0, 25.0, 3000.0, "entered")

    # --- circles as no-fly-zones against legs -----------------------------------------------------
    # 60 km leg passing 1.2 km outside a 20 km circle (Po valley).
    a, b = (45.00, 9.50), direct((45.00, 9.50), 95.0, 60_000.0)
    q, az = on_leg(a, b, 0.5)
    add("leg_60km_nfz_circle_20km_clear",
        leg_text(a, b),
        zone_text("nfz", "circle", (local(q, az, 0.0, 21_200.0), 20_000.0)))
    # 40 km leg cutting 400 m into a 5 km circle.
    a, b = (52.30, 4.70), direct((52.30, 4.70), 140.0, 40_000.0)
    q, az = on_leg(a, b, 0.7)
    add("leg_40km_nfz_circle_5km_entered",
        leg_text(a, b),
        zone_text("nfz", "circle", (local(q, az, 0.0, -4600.0), 5000.0)))
    # 8 km leg passing 8 m outside a 100 m circle.
    a, b = (47.05, 8.30), direct((47.05, 8.30), 10.0, 8_000.0)
    q, az = on_leg(a, b, 0.5)
    add("leg_8km_nfz_circle_100m_grazing",
        leg_text(a, b),
        zone_text("nfz", "circle", (local(q, az, 0.0, 108.0), 100.0)))

    # --- fly-zones -------------------------------------------------------------------------------
    # Convex fly-zone around a 12 km leg; nearest edge about 900 m away.
    a, b = (48.20, 11.50), direct((48.20, 11.50), 75.0, 12_000.0)
    add("leg_inside_convex_fz",
        leg_text(a, b),
        zone_text("fz", "polygon", polygon_local(a, 75.0, [
            (-1500, -900), (6000, -1300), (13500, -800), (14000, 700), (6000, 1600),
            (-1200, 1000)])))
    # Concave fly-zone with a V-shaped notch; the leg joins the two sides across the notch,
    # whose tip is 250 m beyond the track: the leg is about 210 m outside at the deepest.
    a, b = (48.30, 11.70), direct((48.30, 11.70), 90.0, 10_000.0)
    add("leg_cuts_concave_fz_notch",
        leg_text(a, b),
        zone_text("fz", "polygon", polygon_local(a, 90.0, [
            (-1000, -1500), (11000, -1500), (11000, 1000), (7000, 1000), (5000, -250),
            (3000, 1000), (-1000, 1000)])))
    # Take-off point 150 m outside a fly-zone's edge.
    fz = polygon_polar((48.25, 11.62), [(10.0, 3000.0), (100.0, 2500.0), (190.0, 3200.0),
                                       (280.0, 2800.0)])
    mid, eaz = on_leg(fz[0], fz[1], 0.4)
    add("point_outside_fz",
        point_text(direct(mid, eaz - 90.0, 150.0)),
        zone_text("fz", "polygon", fz))
    # Point inside a high-latitude fly-zone, 1.9 km from its nearest edge.
    add("point_inside_fz_lat78",
        point_text((78.22, 15.65)),
        zone_text("fz", "polygon", polygon_polar((78.22, 15.65), [
            (0.0, 3500.0), (70.0, 2450.0), (150.0, 2940.0), (220.0, 2100.0), (300.0, 3150.0)])))

    # --- points ----------------------------------------------------------------------------------
    # Take-off point 80 m inside a no-fly polygon.
    nfz = polygon_polar((48.27, 11.66), [(30.0, 900.0), (120.0, 700.0), (210.0, 1000.0),
                                        (300.0, 800.0)])
    mid, eaz = on_leg(nfz[1], nfz[2], 0.5)
    add("point_takeoff_inside_nfz_polygon",
        point_text(direct(mid, eaz + 90.0, 80.0)),
        zone_text("nfz", "polygon", nfz))
    # Point 30 m beyond a convex vertex (the vertex is the closest border point).
    nfz = polygon_polar((47.40, 8.55), [(0.0, 1200.0), (100.0, 900.0), (170.0, 1500.0),
                                       (250.0, 1000.0), (320.0, 1100.0)])
    add("point_near_nfz_vertex",
        point_text(direct((47.40, 8.55), 100.0, 930.0)),
        zone_text("nfz", "polygon", nfz))
    # Point 35 m inside a 250 m no-fly circle.
    add("point_inside_nfz_circle",
        point_text(direct((50.05, 8.57), 222.0, 215.0)),
        zone_text("nfz", "circle", ((50.05, 8.57), 250.0)))

    # --- short and long legs -----------------------------------------------------------------
    # 300 m leg, 12 m from a quadrilateral's vertex.
    a, b = (48.2650, 11.6700), direct((48.2650, 11.6700), 45.0, 300.0)
    q, az = on_leg(a, b, 0.5)
    add("leg_300m_nfz_near",
        leg_text(a, b),
        zone_text("nfz", "polygon", polygon_local(q, az, [
            (-200, 30), (0, 12), (250, 35), (60, 400)])))
    # Leg whose end point is 60 m inside a no-fly-zone (the depth is greatest at the end).
    a, b = (46.50, 7.00), direct((46.50, 7.00), 200.0, 20_000.0)
    add("leg_end_inside_nfz",
        leg_text(a, b),
        zone_text("nfz", "polygon", polygon_local(b, 200.0, [
            (-60, -900), (-60, 800), (1500, 1200), (1800, -700)])))
    # 250 km leg at 55 N (Jutland to Skane) passing right through a 900 m wide no-fly corridor:
    # the depth is the half width.
    a, b = (55.70, 8.50), direct((55.70, 8.50), 95.0, 250_000.0)
    q, az = on_leg(a, b, 0.6)
    add("leg_250km_through_nfz",
        leg_text(a, b),
        zone_text("nfz", "polygon", polygon_local(q, az, [
            (-450, -6000), (450, -6000), (450, 7000), (-450, 7000)])))
    # 100 km leg crossing a no-fly pentagon: the depth is the inradius-like ridge point.
    a, b = (40.40, -3.70), direct((40.40, -3.70), 30.0, 100_000.0)
    q, az = on_leg(a, b, 0.5)
    add("leg_100km_crossing_nfz_deep",
        leg_text(a, b),
        zone_text("nfz", "polygon", polygon_local(q, az, [
            (-360, -420), (300, -540), (540, 240), (-60, 660), (-540, 180)])))
    return out


# ---------------------------------------------------------------------------------------------


def compute(settings, err):
    started = time.time()
    results = []
    for name, ptext, ztext in rows():
        if ONLY and name not in ONLY:
            continue
        t0 = time.time()
        path = parse_path(ptext)
        zone = parse_zone(ztext, settings)
        margin, t = path_margin(path, zone, settings)
        at = path.at(t)
        results.append((name, ptext, ztext, margin, at))
        flat_mm = flat_stretch(path, zone, t, margin, 1e-3)
        flat_half = flat_stretch(path, zone, t, margin, 0.5)
        err.write("%-42s margin %10.3f m at %s; within 1 mm / 0.5 m of it over %.1f / %.0f m"
                  " (%.1f s)\n"
                  % (name, margin, fmt_pos(at), flat_mm, flat_half, time.time() - t0))
        err.flush()
    err.write("%d rows in %.0f s\n" % (len(results), time.time() - started))
    return results


# Row names given after --only: compute just those (to try a row out; never for the CSV).
ONLY = set()


def main():
    if "--only" in sys.argv[1:]:
        ONLY.update(sys.argv[sys.argv.index("--only") + 1:])
    check = "--check" in sys.argv[1:]
    if check:
        normal = compute(NORMAL, sys.stderr)
        fine = compute(FINE, sys.stderr)
        worst = 0.0
        for n, f in zip(normal, fine):
            dm = abs(n[3] - f[3])
            dpos = inverse_dist(n[4][0], n[4][1], f[4][0], f[4][1])
            worst = max(worst, dm)
            print("%-44s d_margin %.6f m  d_at %.3f m" % (n[0], dm, dpos))
        print("largest margin difference, normal vs fine settings: %.6f m" % worst)
        return
    results = compute(NORMAL, sys.stderr)
    out = sys.stdout
    out.write("# Geofence accuracy reference (geofence_accuracy.rs): signed margin of a path against one zone,\n")
    out.write("# geodesic metres on WGS-84, before any safety offset; negative = the path reaches the\n")
    out.write("# forbidden side (inside a nfz, outside a fz) and |margin| is the greatest depth there.\n")
    out.write("# at_lat,at_lon: where on the path the margin is reached. Semantics: README.md here.\n")
    out.write("# Computed independently with GeographicLib %s (Python), Geodesic.WGS84, by:\n"
              % geographiclib.__version__)
    out.write("#   python3 services/protocol/tests/data/geofence_reference.py"
              " > services/protocol/tests/data/geofence_accuracy.csv\n")
    out.write("name,path,zone,margin_m,at_lat,at_lon\n")
    for name, ptext, ztext, margin, at in results:
        m = "%.3f" % margin
        if m == "-0.000":
            m = "0.000"
        out.write("%s,%s,%s,%s,%s,%s\n"
                  % (name, ptext, ztext, m, fmt_deg(at[0]), fmt_deg(norm_lon(at[1]))))


if __name__ == "__main__":
    main()
