#!/usr/bin/env python3
"""Generates the colour tables in this folder (256 rows of r,g,b in [0, 1]).

Run from anywhere: python3 assets/colormaps/generate_colormaps.py   (standard library only)

How the tables are made (our own computation, no table is copied):
  viridis, magma  A smooth path in CAM02-UCS (CIECAM02 with the viewing conditions viscm uses:
                  sRGB white scaled to Y = 100, L_A = 64/pi/5 cd/m^2, Y_b = 20, average surround;
                  Luo, Cui & Li 2006 UCS: J' = 1.7 J / (1 + 0.007 J), M' = ln(1 + 0.0228 M)/0.0228)
                  through the five colours that define each map at t = 0, 1/4, 1/2, 3/4, 1 (the
                  well-known 5-colour samples of matplotlib's maps), as natural cubic splines in
                  J', a', b' over t. The path is resampled at equal steps of its length in that space,
                  so neighbouring entries are equally far apart perceptually and lightness rises
                  monotonically. UCS -> sRGB is solved by Newton iteration on the forward model.
                  The fit reproduces the anchors closely; it is a relative of matplotlib's map, not a copy.
  coolwarm        Diverging map by K. Moreland's method ("Diverging Color Maps for Scientific
                  Visualization", 2009): interpolate in his polar Msh space (M = |Lab|,
                  s = acos(L*/M), h = atan2(b*, a*)) from blue (59, 76, 192) through a neutral
                  white to red (180, 4, 38), with the hue spin he prescribes near the midpoint.
The script prints per-map checks (anchor error, spread of step sizes, out-of-gamut clipping).
"""
import math
import os

HERE = os.path.dirname(os.path.abspath(__file__))
N = 256

# ---- colour science: sRGB <-> CIE L*a*b* (D65) --------------------------------------------------
WHITE = (0.95047, 1.0, 1.08883)


def srgb_to_linear(c):
    return c / 12.92 if c <= 0.04045 else ((c + 0.055) / 1.055) ** 2.4


def linear_to_srgb(c):
    return 12.92 * c if c <= 0.0031308 else 1.055 * c ** (1 / 2.4) - 0.055


def rgb_to_lab(rgb):
    r, g, b = (srgb_to_linear(c) for c in rgb)
    x = 0.4124564 * r + 0.3575761 * g + 0.1804375 * b
    y = 0.2126729 * r + 0.7151522 * g + 0.0721750 * b
    z = 0.0193339 * r + 0.1191920 * g + 0.9503041 * b

    def f(t):
        return t ** (1 / 3) if t > (6 / 29) ** 3 else t / (3 * (6 / 29) ** 2) + 4 / 29

    fx, fy, fz = f(x / WHITE[0]), f(y / WHITE[1]), f(z / WHITE[2])
    return (116 * fy - 16, 500 * (fx - fy), 200 * (fy - fz))


def lab_to_rgb(lab):
    L, a, b = lab
    fy = (L + 16) / 116
    fx, fz = fy + a / 500, fy - b / 200

    def finv(t):
        return t ** 3 if t > 6 / 29 else 3 * (6 / 29) ** 2 * (t - 4 / 29)

    x, y, z = WHITE[0] * finv(fx), WHITE[1] * finv(fy), WHITE[2] * finv(fz)
    r = 3.2404542 * x - 1.5371385 * y - 0.4985314 * z
    g = -0.9692660 * x + 1.8760108 * y + 0.0415560 * z
    bb = 0.0556434 * x - 0.2040259 * y + 1.0572252 * z
    out = [linear_to_srgb(min(max(c, 0.0), 1.0)) for c in (r, g, bb)]
    clipped = any(c < -1e-4 or c > 1 + 1e-4 for c in (r, g, bb))
    return out, clipped


# ---- CIECAM02 / CAM02-UCS (forward; inverse by Newton iteration) -------------------------------
def inv3(m):
    a,b,c=m[0];d,e,f=m[1];g,h,i=m[2]
    det=a*(e*i-f*h)-b*(d*i-f*g)+c*(d*h-e*g)
    return [[(e*i-f*h)/det,(c*h-b*i)/det,(b*f-c*e)/det],[(f*g-d*i)/det,(a*i-c*g)/det,(c*d-a*f)/det],[(d*h-e*g)/det,(b*g-a*h)/det,(a*e-b*d)/det]]
def mul(m,v): return [sum(m[r][k]*v[k] for k in range(3)) for r in range(3)]
def mm(a,b): return [[sum(a[r][k]*b[k][c] for k in range(3)) for c in range(3)] for r in range(3)]
CAT=[[0.7328,0.4296,-0.1624],[-0.7036,1.6975,0.0061],[0.0030,0.0136,0.9834]]
HPE=[[0.38971,0.68898,-0.07868],[-0.22981,1.18340,0.04641],[0.0,0.0,1.0]]
HC=mm(HPE,inv3(CAT))
XW=[95.047,100.0,108.883]; LA=64/math.pi/5; YB=20.0; F,c,Nc=1.0,0.69,1.0
D=min(1,max(0,F*(1-(1/3.6)*math.exp((-LA-42)/92))))
k=1/(5*LA+1); FL=0.2*k**4*(5*LA)+0.1*(1-k**4)**2*(5*LA)**(1/3)
n=YB/XW[1]; Nbb=0.725*(1/n)**0.2; z=1.48+math.sqrt(n)
RGBw=mul(CAT,XW)
Dk=[XW[1]*D/RGBw[i]+1-D for i in range(3)]
def adapt(v):
    x=FL*abs(v)/100
    p=x**0.42
    return math.copysign(400*p/(27.13+p),v)+0.1
def pre(XYZ):
    rgb=mul(CAT,XYZ); rgbc=[Dk[i]*rgb[i] for i in range(3)]
    r=mul(HC,rgbc); return [adapt(v) for v in r]
Rw=pre(XW); Aw=(2*Rw[0]+Rw[1]+Rw[2]/20-0.305)*Nbb
def xyz_to_ucs(XYZ):
    Ra,Ga,Ba=pre(XYZ)
    a=Ra-12*Ga/11+Ba/11; b=(Ra+Ga-2*Ba)/9
    h=math.atan2(b,a)
    et=0.25*(math.cos(h+2)+3.8)
    A=(2*Ra+Ga+Ba/20-0.305)*Nbb
    J=100*(max(A,0)/Aw)**(c*z)
    t=(50000/13*Nc*Nbb*et*math.hypot(a,b))/(Ra+Ga+21/20*Ba)
    C=t**0.9*math.sqrt(J/100)*(1.64-0.29**n)**0.73
    M=C*FL**0.25
    Jp=1.7*J/(1+0.007*J); Mp=math.log(1+0.0228*M)/0.0228
    return (Jp,Mp*math.cos(h),Mp*math.sin(h))


def rgb_to_xyz100(rgb):
    r, g, b = (srgb_to_linear(c) for c in rgb)
    return [100 * (0.4124564 * r + 0.3575761 * g + 0.1804375 * b),
            100 * (0.2126729 * r + 0.7151522 * g + 0.0721750 * b),
            100 * (0.0193339 * r + 0.1191920 * g + 0.9503041 * b)]


def xyz100_to_linear_rgb(x):
    x, y, z = (v / 100 for v in x)
    return [3.2404542 * x - 1.5371385 * y - 0.4985314 * z,
            -0.9692660 * x + 1.8760108 * y + 0.0415560 * z,
            0.0556434 * x - 0.2040259 * y + 1.0572252 * z]


def rgb_to_ucs(rgb):
    return xyz_to_ucs(rgb_to_xyz100(rgb))


def ucs_to_rgb(target, start_xyz):
    """sRGB (clipped to [0, 1]) whose CAM02-UCS coordinates are `target`, whether it clipped, and
    the XYZ found (the next point along a path starts from it)."""
    x = list(start_xyz)
    for _ in range(100):
        f0 = xyz_to_ucs(x)
        r = [f0[i] - target[i] for i in range(3)]
        if max(abs(v) for v in r) < 1e-9:
            break
        jac = [[0.0] * 3 for _ in range(3)]
        for j in range(3):
            hstep = 1e-6 * max(1.0, abs(x[j]))
            xp = list(x)
            xp[j] += hstep
            fp = xyz_to_ucs(xp)
            for i in range(3):
                jac[i][j] = (fp[i] - f0[i]) / hstep
        dx = mul(inv3(jac), r)
        x = [x[i] - dx[i] for i in range(3)]
    else:
        raise RuntimeError("CAM02-UCS inversion did not converge for %s" % (target,))
    lin = xyz100_to_linear_rgb(x)
    clipped = any(c < -1e-4 or c > 1 + 1e-4 for c in lin)
    return [linear_to_srgb(min(max(c, 0.0), 1.0)) for c in lin], clipped, x


def hex_rgb(h):
    return tuple(int(h[k:k + 2], 16) / 255 for k in (1, 3, 5))


def delta_e(p, q):
    return math.sqrt(sum((a - b) ** 2 for a, b in zip(p, q)))


# ---- natural cubic spline -----------------------------------------------------------------------
def natural_spline(xs, ys):
    n = len(xs) - 1
    h = [xs[i + 1] - xs[i] for i in range(n)]
    alpha = [0.0] * (n + 1)
    for i in range(1, n):
        alpha[i] = 3 / h[i] * (ys[i + 1] - ys[i]) - 3 / h[i - 1] * (ys[i] - ys[i - 1])
    l, mu, z = [1.0] * (n + 1), [0.0] * (n + 1), [0.0] * (n + 1)
    for i in range(1, n):
        l[i] = 2 * (xs[i + 1] - xs[i - 1]) - h[i - 1] * mu[i - 1]
        mu[i] = h[i] / l[i]
        z[i] = (alpha[i] - h[i - 1] * z[i - 1]) / l[i]
    c, b, d = [0.0] * (n + 1), [0.0] * n, [0.0] * n
    for j in range(n - 1, -1, -1):
        c[j] = z[j] - mu[j] * c[j + 1]
        b[j] = (ys[j + 1] - ys[j]) / h[j] - h[j] * (c[j + 1] + 2 * c[j]) / 3
        d[j] = (c[j + 1] - c[j]) / (3 * h[j])

    def ev(x):
        j = min(max(0, next((k for k in range(n) if x < xs[k + 1]), n - 1)), n - 1)
        dx = x - xs[j]
        return ys[j] + b[j] * dx + c[j] * dx * dx + d[j] * dx ** 3

    return ev


def anchored_uniform_map(anchors_hex):
    """Points in CAM02-UCS, equally spaced along the spline through the anchors."""
    ts = [k / (len(anchors_hex) - 1) for k in range(len(anchors_hex))]
    labs = [rgb_to_ucs(hex_rgb(h)) for h in anchors_hex]
    splines = [natural_spline(ts, [lab[c] for lab in labs]) for c in range(3)]
    # dense path, then equal-arc-length resampling
    m = 20000
    path = [tuple(s(k / m) for s in splines) for k in range(m + 1)]
    arc = [0.0]
    for k in range(m):
        arc.append(arc[-1] + delta_e(path[k], path[k + 1]))
    out, j = [], 0
    for i in range(N):
        target = arc[-1] * i / (N - 1)
        while j < m - 1 and arc[j + 1] < target:
            j += 1
        w = 0.0 if arc[j + 1] == arc[j] else (target - arc[j]) / (arc[j + 1] - arc[j])
        out.append(tuple(path[j][c] * (1 - w) + path[j + 1][c] * w for c in range(3)))
    anchor_err = []
    for t, lab in zip(ts, labs):
        anchor_err.append(delta_e(out[round(t * (N - 1))], lab))
    return out, anchor_err


# ---- Moreland diverging map ---------------------------------------------------------------------
def lab_to_msh(lab):
    L, a, b = lab
    M = math.sqrt(L * L + a * a + b * b)
    return (M, math.acos(L / M) if M > 0 else 0.0, math.atan2(b, a))


def msh_to_lab(msh):
    M, s, h = msh
    return (M * math.cos(s), M * math.sin(s) * math.cos(h), M * math.sin(s) * math.sin(h))


def adjust_hue(msh_sat, m_unsat):
    M, s, h = msh_sat
    if M >= m_unsat:
        return h
    spin = s * math.sqrt(m_unsat ** 2 - M ** 2) / (M * math.sin(s))
    return h + spin if h > -math.pi / 3 else h - spin


def moreland(rgb1, rgb2, t):
    m1, s1, h1 = lab_to_msh(rgb_to_lab(rgb1))
    m2, s2, h2 = lab_to_msh(rgb_to_lab(rgb2))
    if s1 > 0.05 and s2 > 0.05 and abs(h1 - h2) > math.pi / 3:
        mid = max(m1, m2, 88.0)
        if t < 0.5:
            m2, s2, h2, t = mid, 0.0, 0.0, 2 * t
        else:
            m1, s1, h1, t = mid, 0.0, 0.0, 2 * t - 1
    if s1 < 0.05 and s2 > 0.05:
        h1 = adjust_hue((m2, s2, h2), m1)
    elif s2 < 0.05 and s1 > 0.05:
        h2 = adjust_hue((m1, s1, h1), m2)
    return msh_to_lab(((1 - t) * m1 + t * m2, (1 - t) * s1 + t * s2, (1 - t) * h1 + t * h2))


# ---- write --------------------------------------------------------------------------------------
def write(name, rows, note):
    """rows: sRGB triples. Reports lightness and step sizes measured in CAM02-UCS."""
    ucs = [rgb_to_ucs(rgb) for rgb in rows]
    steps = [delta_e(ucs[k], ucs[k + 1]) for k in range(N - 1)]
    mean = sum(steps) / len(steps)
    with open(os.path.join(HERE, name + ".csv"), "w") as f:
        f.write("r,g,b\n")
        for r, g, b in rows:
            f.write("%.6f,%.6f,%.6f\n" % (r, g, b))
    print("%-9s J' %5.1f -> %5.1f  UCS step mean %.3f min %.3f max %.3f  %s" %
          (name, ucs[0][0], ucs[-1][0], mean, min(steps), max(steps), note))


def to_rgb_rows(ucs_points, first_rgb):
    rows, clipped = [], 0
    x = rgb_to_xyz100(first_rgb)
    for p in ucs_points:
        rgb, c, x = ucs_to_rgb(p, x)
        rows.append(rgb)
        clipped += c
    return rows, clipped


for name, anchors in (("viridis", ["#440154", "#3b528b", "#21908c", "#5dc863", "#fde725"]),
                      ("magma", ["#000004", "#51127c", "#b63679", "#fb8861", "#fcfdbf"])):
    points, err = anchored_uniform_map(anchors)
    rows, clipped = to_rgb_rows(points, hex_rgb(anchors[0]))
    write(name, rows, "clipped %d, anchor dE' %s" % (clipped, " ".join("%.2f" % e for e in err)))
blue, red = (59 / 255, 76 / 255, 192 / 255), (180 / 255, 4 / 255, 38 / 255)
rows = [lab_to_rgb(moreland(blue, red, k / (N - 1)))[0] for k in range(N)]
write("coolwarm", rows, "(Moreland Msh; lightness peaks mid-map by design)")
