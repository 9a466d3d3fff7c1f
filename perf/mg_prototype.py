#!/usr/bin/env python3
"""Prototype (numpy/scipy, not dcm's code) of multigrid variants for the velocity solve's operator
Gamma (+ dt K_bend): cold-start PCG iterations to 1e-8 relative on a perturbed icosphere of the paper's
cell, for the V-cycle dcm uses (point block-Jacobi smoother, linear prolongation on the subdivision
hierarchy, Galerkin coarse levels) and two candidate cures of its mesh dependence: a smoothed
prolongation P_s = (I - w D^-1 A) P and an additive vertex-star (patch) smoother.
docs/model/solver.md reports what it printed.

  python3 perf/mg_prototype.py --level 4 --variant plain|smoothed_p|star [--bending] [--perturbation 0.002]
"""
import argparse
import numpy as np
import scipy.sparse as sp
import scipy.sparse.linalg as sla
def icosphere(k):
    t=(1+5**.5)/2
    v=[(-1,t,0),(1,t,0),(-1,-t,0),(1,-t,0),(0,-1,t),(0,1,t),(0,-1,-t),(0,1,-t),(t,0,-1),(t,0,1),(-t,0,-1),(-t,0,1)]
    f=[(0,11,5),(0,5,1),(0,1,7),(0,7,10),(0,10,11),(1,5,9),(5,11,4),(11,10,2),(10,7,6),(7,1,8),(3,9,4),(3,4,2),(3,2,6),(3,6,8),(3,8,9),(4,9,5),(2,4,11),(6,2,10),(8,6,7),(9,8,1)]
    v=[np.array(x,float)/np.linalg.norm(x) for x in v]; parents=[(i,i) for i in range(12)]
    levels=[len(v)]
    for _ in range(k):
        mid={}; nf=[]
        def m(a,b):
            key=(min(a,b),max(a,b))
            if key not in mid:
                p=v[a]+v[b]; v.append(p/np.linalg.norm(p)); parents.append(key); mid[key]=len(v)-1
            return mid[key]
        for a,b,c in f:
            ab,bc,ca=m(a,b),m(b,c),m(c,a); nf+= [(a,ab,ca),(b,bc,ab),(c,ca,bc),(ab,bc,ca)]
        f=nf; levels.append(len(v))
    return np.array(v),np.array(f),parents,levels
def edges(f):
    e=set()
    for a,b,c in f:
        for x,y in ((a,b),(b,c),(c,a)): e.add((min(x,y),max(x,y)))
    return np.array(sorted(e))
def gamma(x,E,zeta,c):
    n=len(x); rows=[];cols=[];vals=[]
    d=x[E[:,1]]-x[E[:,0]]; d/=np.linalg.norm(d,axis=1)[:,None]
    for (i,j),u in zip(E,d):
        M=c*np.outer(u,u)
        for (p,q,s) in ((i,i,1),(j,j,1),(i,j,-1),(j,i,-1)):
            for a in range(3):
                for b in range(3):
                    rows.append(3*p+a);cols.append(3*q+b);vals.append(s*M[a,b])
    A=sp.csr_matrix((vals,(rows,cols)),shape=(3*n,3*n))
    return A+zeta*sp.identity(3*n)
def prolong(parents,nf,nc):
    r=[];c=[];v=[]
    for i in range(nf):
        p=parents[i]
        for a in range(3):
            if p[0]==p[1]: r.append(3*i+a);c.append(3*p[0]+a);v.append(1.0)
            else:
                r+= [3*i+a,3*i+a]; c+=[3*p[0]+a,3*p[1]+a]; v+=[.5,.5]
    return sp.csr_matrix((v,(r,c)),shape=(3*nf,3*nc))
def blockdiag_inv(A):
    n=A.shape[0]//3; blocks=[]
    Ad=A.tocsr()
    for i in range(n):
        B=Ad[3*i:3*i+3,3*i:3*i+3].toarray(); blocks.append(np.linalg.inv(B))
    return sp.block_diag(blocks,format='csr')
class MG:
    def __init__(s,A,Ps,nu=2,om=0.6,smooth_p=0,filt=False):
        s.A=[A];s.P=[];s.Dinv=[]
        for P in Ps:
            Al=s.A[-1]; Di=blockdiag_inv(Al)
            if smooth_p:
                lam=sla.eigs(Di@Al,k=1,which='LM',return_eigenvectors=False)[0].real
                w=smooth_p/lam
                P=P-w*(Di@(Al@P))
            s.P.append(P.tocsr()); s.A.append((P.T@Al@P).tocsr())
        s.Dinv=[blockdiag_inv(Al) for Al in s.A[:-1]]
        s.coarse=np.linalg.inv(s.A[-1].toarray()); s.nu=nu;s.om=om
    def vc(s,l,b):
        if l==len(s.A)-1: return s.coarse@b
        A=s.A[l];D=s.Dinv[l];x=s.om*(D@b)
        for _ in range(s.nu-1): x+=s.om*(D@(b-A@x))
        r=b-A@x; x+=s.P[l]@s.vc(l+1,s.P[l].T@r)
        for _ in range(s.nu): x+=s.om*(D@(b-A@x))
        return x
def pcg(A,b,M,tol=1e-8,maxit=5000):
    x=np.zeros_like(b);r=b.copy();z=M(r);p=z.copy();rz=r@z;nb=np.linalg.norm(b)
    for it in range(1,maxit+1):
        q=A@p;al=rz/(p@q);x+=al*p;r-=al*q
        if np.linalg.norm(r)<tol*nb: return it
        z=M(r);rz2=r@z;p=z+rz2/rz*p;rz=rz2
    return maxit
def hinges(f):
    d={}
    for t,(a,b,c) in enumerate(f):
        for x,y,z in ((a,b,c),(b,c,a),(c,a,b)):
            d.setdefault((min(x,y),max(x,y)),[]).append(z)
    return np.array([(i,j,w[0],w[1]) for (i,j),w in d.items()])
def dihedral(X):  # X: (H,4,3) edge i,j, wings k,l
    i,j,k,l=X[:,0],X[:,1],X[:,2],X[:,3]
    e=j-i; n1=np.cross(k-i,e); n2=np.cross(e,l-i)
    en=e/np.linalg.norm(e,axis=1)[:,None]
    return np.arctan2(np.einsum('ij,ij->i',np.cross(n1,n2),en), np.einsum('ij,ij->i',n1,n2))
def kbend(x,H,s):
    X=x[H]; g=np.zeros(X.shape); h=1e-6*np.linalg.norm(X[:,1]-X[:,0],axis=1)
    for a in range(4):
        for c in range(3):
            Xp=X.copy();Xm=X.copy();Xp[:,a,c]+=h;Xm[:,a,c]-=h
            g[:,a,c]=(dihedral(Xp)-dihedral(Xm))/(2*h)
    rows=[];cols=[];vals=[]
    n=len(x)
    for hh in range(len(H)):
        G=g[hh].reshape(12)
        idx=np.concatenate([3*H[hh][a]+np.arange(3) for a in range(4)])
        M=s*np.outer(G,G)
        rows.append(np.repeat(idx,12)); cols.append(np.tile(idx,12)); vals.append(M.ravel())
    return sp.csr_matrix((np.concatenate(vals),(np.concatenate(rows),np.concatenate(cols))),shape=(3*n,3*n))

class Patch:
    """Additive Schwarz over vertex stars, damped by 1/(largest overlap)."""
    def __init__(s, A, patches):
        s.A = A.tocsr(); s.p = []
        count = np.zeros(A.shape[0] // 3)
        for P in patches: count[P] += 1
        s.om = 1.0 / count.max()
        for P in patches:
            idx = np.concatenate([3 * q + np.arange(3) for q in P])
            s.p.append((idx, np.linalg.inv(s.A[idx][:, idx].toarray())))
    def __call__(s, r):
        z = np.zeros_like(r)
        for idx, Ai in s.p: z[idx] += Ai @ r[idx]
        return s.om * z

class MGStar(MG):
    def __init__(s, A, Ps, nu=2):
        s.A = [A.tocsr()]; s.P = []
        for P in Ps: s.P.append(P.tocsr()); s.A.append((P.T @ s.A[-1] @ P).tocsr())
        s.S = []
        for Al in s.A[:-1]:
            n = Al.shape[0] // 3
            s.S.append(Patch(Al, [sorted(set(Al.indices[Al.indptr[3 * i]:Al.indptr[3 * i + 1]] // 3)) for i in range(n)]))
        s.coarse = np.linalg.inv(s.A[-1].toarray()); s.nu = nu
    def vc(s, l, b):
        if l == len(s.A) - 1: return s.coarse @ b
        A = s.A[l]; S = s.S[l]; x = S(b)
        for _ in range(s.nu - 1): x += S(b - A @ x)
        r = b - A @ x; x += s.P[l] @ s.vc(l + 1, s.P[l].T @ r)
        for _ in range(s.nu): x += S(b - A @ x)
        return x

def main():
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--level", type=int, default=3, help="icosphere subdivisions (3: 642 nodes, 4: 2562)")
    ap.add_argument("--variant", choices=["plain", "smoothed_p", "star"], default="plain")
    ap.add_argument("--bending", action="store_true", help="add dt k_b grad(theta) grad(theta)^T (dt = 6 us)")
    ap.add_argument("--perturbation", type=float, default=0.002, help="relative radial noise of the nodes")
    a = ap.parse_args()
    R, eta, c, dt, kb = 3.25e-6, 0.8e-3, 1.5e-6, 6e-6, 2.4e-19
    v, f, par, lev = icosphere(a.level)
    rng = np.random.default_rng(1)
    x = R * v * (1 + a.perturbation * rng.standard_normal((len(v), 1)))
    E = edges(f); n = len(x); zeta = 6 * np.pi * eta * R / n
    A = gamma(x, E, zeta, c)
    if a.bending: A = (A + kbend(x, hinges(f), dt * kb)).tocsr()
    Ps = [prolong(par, lev[l], lev[l - 1]) for l in range(a.level, 0, -1)]
    b = rng.standard_normal(3 * n)
    if a.variant == "star": mg = MGStar(A, Ps)
    else: mg = MG(A, Ps, smooth_p=4.0 / 3.0 if a.variant == "smoothed_p" else 0)
    its = pcg(A, b, lambda r: mg.vc(0, r))
    print(f"nodes {n} variant {a.variant} bending {a.bending} perturbation {a.perturbation}: {its} PCG iterations")

if __name__ == "__main__":
    main()
