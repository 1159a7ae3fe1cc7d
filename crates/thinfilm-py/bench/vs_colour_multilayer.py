"""Speed of thinfilm.rt against colour-science's multilayer_tmm on a 5-layer stack over
wavelength 360-830 nm by 1 and angles 0-75 deg by 7.5 (5 181 points), one process, best
of 7 each, unpolarised R. Needs `pip install colour-science numpy` and this package.
"""

import time, numpy as np, thinfilm, os
from colour.phenomena import multilayer_tmm
wl = np.arange(360, 831.0); angle = np.arange(0, 75.0 + 1e-9, 7.5)
n = [1.0, 1.38, 2.1, 1.46, 2.1, 1.38, 1.52]; d = [100.0, 60.0, 90.0, 60.0, 100.0]
def best(f, k=7):
    ts=[]
    for _ in range(k):
        s=time.perf_counter(); out=f(); ts.append(time.perf_counter()-s)
    return min(ts), out
t1,(r1,_) = best(lambda: thinfilm.rt(n, d, wl[None,:], angle[:,None]))
t2,res = best(lambda: multilayer_tmm(n, d, wl, angle))
R = np.asarray(res[0]); Ru = np.squeeze(0.5*(R[...,0]+R[...,1])).T
print("load %.2f: rt %.2f ms, colour multilayer_tmm %.2f ms, ratio %.1fx, max|dR| %.1e" % (os.getloadavg()[0], 1e3*t1, 1e3*t2, t2/t1, np.abs(Ru - r1).max()))
