# Reference solve for the resting column of examples/rest.rs (README, "A tank at rest").
#
# Each implicit Euler step minimises (m/2dt^2)|X - s|^2 + (K/2) sum_i max(C_i, 0)^2 with
# K = k*c/D0, the energy whose stationary point the `uniform` weighting with a constant
# projection denominator D0 iterates to, by Gauss-Newton with a Jacobi-preconditioned CG and a
# backtracking line search, until the largest gradient entry is below 1e-8 m in position
# units; then v = (X - x)/dt and the XSPH filter. Needs numpy and scipy.
#
#   BDUMP=/tmp/bnd.bin cargo run --release --example rest -- 3e-3 chebyshev 0.85 0.01 1
#   BND=/tmp/bnd.bin [LOAD=state.bin] python3 tools/rest_reference.py SECONDS
#
# LOAD takes a state written by the rest example's SAVE (positions, then velocities, f64).
import numpy as np, sys, os
from scipy.spatial import cKDTree
import scipy.sparse as sp
from scipy.sparse.linalg import cg
r=0.025; d=2*r; H=4*r; rho0=1000.; m=rho0*d**3; k=5e4; dt=5e-3; g=np.array([0,-9.81,0])
XS=float(os.environ.get("XSPH","0.01")); T=float(sys.argv[1]) if len(sys.argv)>1 else 2.0
sig=8/(np.pi*H**3)
def W(q): return sig*(2*np.clip(1-q,0,None)**3-8*np.clip(0.5-q,0,None)**3)
def dWf(q):  # dW/dr / |r| * ... returns factor f s.t. gradW = f * rvec
    f=np.where(q<=0.5, q*(3*q-2), -(1-q)**2); f=np.where(q>1,0,f)
    return (48/(np.pi*H**3))/H*f
b=np.fromfile(os.environ['BND']).reshape(-1,3)
tb=cKDTree(b)
# Akinci volumes
pb=tb.sparse_distance_matrix(tb,H,output_type='coo_matrix')
psi=rho0/(W(0)+np.bincount(pb.row, W(pb.data/H)*(pb.row!=pb.col), minlength=len(b)))
c=rho0*(4/3)*np.pi*H**3/m; D0=float(os.environ.get("D0","170")); K=k*c/D0*float(os.environ.get("KS","1"))
if os.environ.get("LOAD"):
    f=np.fromfile(os.environ["LOAD"]); x=f[:len(f)//2].reshape(-1,3); v=f[len(f)//2:].reshape(-1,3)
else:
    I=np.stack(np.meshgrid(np.arange(12),np.arange(16),np.arange(12),indexing='ij'),-1).reshape(-1,3)
    x=d*(1+I.astype(float)); v=np.zeros_like(x)
N=len(x)
def pairs(X):
    t=cKDTree(X); P=t.query_pairs(H,output_type='ndarray')
    B=t.sparse_distance_matrix(tb,H,output_type='coo_matrix')
    return P,B
def geom(X,P,B):
    i,j=P[:,0],P[:,1]; rij=X[i]-X[j]; dij=np.linalg.norm(rij,axis=1); q=dij/H
    rb=X[B.row]-b[B.col]; qb=np.linalg.norm(rb,axis=1)/H
    rho=m*W(0)+m*np.bincount(i,W(q),N)+m*np.bincount(j,W(q),N)+np.bincount(B.row,psi[B.col]*W(qb),N)
    C=rho/rho0-1
    gij=(dWf(q)/np.maximum(dij,1e-12))[:,None]*rij   # grad_xi W(xi-xj)
    gb=(dWf(qb)/np.maximum(qb*H,1e-12))[:,None]*rb*psi[B.col][:,None]
    return C,gij,gb
def energy_grad(X,s,P,B):
    C,gij,gb=geom(X,P,B); Cp=np.maximum(C,0); i,j=P[:,0],P[:,1]
    E=0.5*m/dt**2*((X-s)**2).sum()+0.5*K*(Cp**2).sum()
    # grad_j = K/rho0 [ sum_k m (Cj+Ck) gradW_jk + Cj sum_b psi gradW_jb ]
    w=(m*(Cp[i]+Cp[j]))[:,None]*gij
    G=np.zeros_like(X)
    for a in range(3):
        G[:,a]=np.bincount(i,w[:,a],N)-np.bincount(j,w[:,a],N)+Cp*np.bincount(B.row,gb[:,a],N)
    G=m/dt**2*(X-s)+K/rho0*G
    return E,G,C,gij,gb
def jac(C,gij,gb,P,B):
    # rows: active constraints i; d C_i / d x_j
    i,j=P[:,0],P[:,1]; rows=[];cols=[];vals=[]
    for a in range(3):
        # dC_i/dx_j = -(m/rho0) gradW(xi-xj); dC_j/dx_i = -(m/rho0) gradW(xj-xi)=+(m/rho0)gij
        rows+= [i,j]; cols+=[3*j+a,3*i+a]; vals+=[-(m/rho0)*gij[:,a], (m/rho0)*gij[:,a]]
        selfv=(m/rho0)*(np.bincount(i,gij[:,a],N)-np.bincount(j,gij[:,a],N))+np.bincount(B.row,gb[:,a],N)/rho0
        rows.append(np.arange(N)); cols.append(3*np.arange(N)+a); vals.append(selfv)
    Jm=sp.csr_matrix((np.concatenate(vals),(np.concatenate(rows),np.concatenate(cols))),shape=(N,3*N))
    act=sp.diags((C>0).astype(float))
    return act@Jm
GT=float(os.environ.get("GT","1e-8"))
t=0.0; step=0; out=float(os.environ.get("EVERY","0.25")); nxt=out
while t<T-1e-9:
    s=x+dt*v+dt*dt*g; X=s.copy(); P,B=pairs(s)
    for it in range(30):
        E,G,C,gij,gb=energy_grad(X,s,P,B)
        gn=np.abs(G).max()/(m/dt**2)
        if os.environ.get("DBG"): print(it, gn, E, flush=True)
        if gn<GT: break
        Jm=jac(C,gij,gb,P,B)
        Hop=sp.linalg.LinearOperator((3*N,3*N),matvec=lambda u: m/dt**2*u+K*(Jm.T@(Jm@u)))
        dg=m/dt**2+K*np.asarray(Jm.multiply(Jm).sum(0)).ravel()
        Mop=sp.linalg.LinearOperator((3*N,3*N),matvec=lambda u: u/dg)
        dx,info=cg(Hop,-G.ravel(),M=Mop,rtol=1e-8,maxiter=2000)
        dx=dx.reshape(-1,3); a=1.0
        while True:
            E2=energy_grad(X+a*dx,s,P,B)[0]
            if E2<=E+1e-4*a*(G*dx).sum() or a<1e-4: break
            a*=0.5
        X=X+a*dx
        if os.environ.get("DBG"): print("  alpha",a,"cg",info,flush=True)
    vn=(X-x)/dt; x=X
    C,gij,gb=geom(x,P,B); rho=rho0*(C+1)
    if XS>0:
        i,j=P[:,0],P[:,1]; q=np.linalg.norm(x[i]-x[j],axis=1)/H; w=W(q)
        dv=np.zeros_like(vn)
        for a_ in range(3):
            dv[:,a_]=np.bincount(i,(m/rho[j])*w*(vn[j,a_]-vn[i,a_]),N)+np.bincount(j,(m/rho[i])*w*(vn[i,a_]-vn[j,a_]),N)
        vn=vn+XS*dv
    v=vn; t+=dt; step+=1
    if t>=nxt-1e-9:
        print(f"t {t:.2f} rms {np.sqrt((v**2).sum(1).mean()):.4f} ycom {x[:,1].mean():.6f} newton {it} gn {gn:.1e} err {np.maximum(C,0).mean()*100:.4f}% ek {0.5*m*(v**2).sum():.3e}",flush=True)
        nxt+=out
