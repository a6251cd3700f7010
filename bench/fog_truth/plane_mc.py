#!/usr/bin/python3
"""The infinite plane in homogeneous fog, by Monte Carlo (slab transport).

    /usr/bin/python3 bench/fog_truth/plane_mc.py SIGMA_A SIGMA_S G

A plane of radiance L at distance D, fog in front (and, first column, also
behind the camera): by reciprocity the camera sees L times the chance that
a path traced back from the camera reaches the plane. Printed beside
exp(-st D) (unscattered), exp(-sa D) (the paper's L_at + L_sc) and
exp(-sqrt(3 sa s_tr) D) (diffusion's attenuation). Used to test the
rejected diffusion-attenuated spread (docs/multiple-scattering.md).
"""
def hg_cos(g, u):
    if abs(g) < 1e-6: return 2*u-1
    s = (1-g*g)/(1-g+2*g*u)
    return (1+g*g-s*s)/(2*g)
def reach(D, sa, ss, g, behind=True, n=200000, seed=1):
    rng = np.random.default_rng(seed)
    st = sa+ss; om = ss/st
    z = np.zeros(n); mu = np.ones(n); w = np.ones(n); got = 0.0; direct=0.0
    alive = np.ones(n, bool)
    for it in range(400):
        t = -np.log(rng.random(n))/st
        zn = z + mu*t
        hit = alive & (zn >= D)
        got += w[hit].sum()
        if it == 0: direct = w[hit].sum()
        alive &= ~hit
        if not behind:
            alive &= zn > 0  # escaped back out of the slab
        z = zn; w = w*om
        # new direction: HG about the old one
        c = hg_cos(g, rng.random(n)); phi = 2*np.pi*rng.random(n)
        sin_t = np.sqrt(np.maximum(0, 1-c*c)); sin_m = np.sqrt(np.maximum(0, 1-mu*mu))
        mu = mu*c + sin_m*sin_t*np.cos(phi)
        if alive.sum() == 0: break
    return got/n, direct/n
sa, ss, g = float(sys.argv[1]), float(sys.argv[2]), float(sys.argv[3])
st=sa+ss; tr=sa+ss*(1-g); sd=min(np.sqrt(3*sa*tr), st)
print("D  T_total(fog behind cam)  T_total(slab only)  exp(-st D)  exp(-sa D)  exp(-sdiff D)")
for D in [1,2,5,10,20,30,50]:
    a,d = reach(D, sa, ss, g, True); b,_ = reach(D, sa, ss, g, False)
    print("%3g  %.4f  %.4f  %.4f  %.4f  %.4f" % (D, a, b, np.exp(-st*D), np.exp(-sa*D), np.exp(-sd*D)))
