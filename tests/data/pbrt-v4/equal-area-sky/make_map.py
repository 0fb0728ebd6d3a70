# Independent reimplementation of the equal-area square -> sphere map (texel centres), writing a PFM.
import numpy as np, sys
n = int(sys.argv[2]) if len(sys.argv) > 2 else 128
u = (np.arange(n) + 0.5) / n
U, V = np.meshgrid(u, u)            # U: column, V: row (row 0 = top)
a, b = 2*U - 1, 2*V - 1
sd = 1 - (abs(a) + abs(b)); r = 1 - abs(sd)
phi = np.where(r == 0, np.pi/4, np.pi/4 * ((abs(b) - abs(a)) / np.maximum(r, 1e-30) + 1))
z = np.copysign(1 - r*r, sd); s = r*np.sqrt(np.maximum(0, 2 - r*r))
x = np.copysign(np.cos(phi)*s, a); y = np.copysign(np.sin(phi)*s, b)
R = 0.4 + 0.3*x; G = 0.4 + 0.3*y; B = 0.3 + 0.4*np.maximum(z, 0)
sun = np.array([0.5, -0.3, 0.8]); sun /= np.linalg.norm(sun)
m = (x*sun[0] + y*sun[1] + z*sun[2]) > np.cos(np.radians(5))
R[m], G[m], B[m] = 60, 50, 40
img = np.stack([R, G, B], -1).astype('<f4')
with open(sys.argv[1], 'wb') as f:
    f.write(b'PF\n%d %d\n-1.0\n' % (n, n))
    f.write(img[::-1].tobytes())   # PFM rows run bottom to top
print('sun texels', m.sum(), 'mean', img.reshape(-1,3).mean(0))
