# Largest eigenvalue of D^-1/2 J J^T D^-1/2 for the density constraints of a periodic 10^3
# lattice (README, "A tank at rest"): the factor by which the summed projection corrections
# overshoot in fully compressed fluid. The plain outer iteration is stable there only if
# gamma * mu_max < 2. Needs numpy.  python3 tools/overshoot_eigenvalue.py
import numpy as np
H=0.1; d=0.05; L=10; rho0=1000.; m=rho0*d**3
def gradW(r):
    n=np.linalg.norm(r,axis=-1); q=n/H
    f=np.where(q<=0.5, q*(3*q-2), -(1-q)**2); f=np.where(q>1,0,f); f=np.where(n<1e-9,0,f)
    return (48/(np.pi*H**3))/H*f[...,None]*r/np.maximum(n,1e-12)[...,None]
def run(scale, jitter, seed=0):
    rng=np.random.default_rng(seed)
    g=np.stack(np.meshgrid(*[np.arange(L)]*3,indexing='ij'),-1).reshape(-1,3)*d*scale
    g=g+rng.normal(0,jitter*d,g.shape)
    N=len(g); box=L*d*scale
    J=np.zeros((N,N,3))
    dx=g[:,None,:]-g[None,:,:]; dx-=box*np.round(dx/box)
    gw=gradW(dx)  # grad wrt x_i of W(x_i-x_j)
    # dC_i/dx_j = -(m/rho0) gw[i,j] for j!=i ; dC_i/dx_i = (m/rho0) sum_j gw[i,j]
    J=-(m/rho0)*gw
    for i in range(N): J[i,i]=(m/rho0)*gw[i].sum(0)
    Jf=J.reshape(N,3*N)
    D=(Jf**2).sum(1)
    A=Jf@Jf.T/np.sqrt(D[:,None]*D[None,:])
    ev=np.linalg.eigvalsh(A)
    nn=(np.linalg.norm(dx,axis=-1)<H).sum(1)-1
    print(f"scale {scale} jitter {jitter}: mu_max {ev[-1]:.3f} mu_min {ev[0]:.3g} n {nn.mean():.1f} D {D.mean():.1f}")
for s,j in [(1,0),(1,0.05),(1,0.15),(0.97,0.1)]: run(s,j)
