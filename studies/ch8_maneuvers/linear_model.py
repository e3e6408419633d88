# The linear model of docs/path_feedforward.md ("Why the J-turns' swing was under-damped"):
# the linear bicycle (6.5)-(6.6) + the path controller (7.13)-(7.18) (x'' the instantaneous
# lateral acceleration) + the rear-steer law (8.5) with Kr linearised about the turn, about
# straight running; Kyaw is K_r (the reference yaw rate is an input: no term in the modes).
# Eigenvalues without numpy (Faddeev-LeVerrier, Durand-Kerner). Run: python3 linear_model.py
import cmath, math, sys
def matmul(A,B):
    n=len(A);m=len(B[0]);k=len(B)
    return [[sum(A[i][l]*B[l][j] for l in range(k)) for j in range(m)] for i in range(n)]
def charpoly(A):
    n=len(A); I=[[float(i==j) for j in range(n)] for i in range(n)]
    c=[1.0]; M=[[0.0]*n for _ in range(n)]
    for k in range(1,n+1):
        AM=matmul(A,M)
        M=[[AM[i][j]+c[-1]*I[i][j] for j in range(n)] for i in range(n)]
        AM=matmul(A,M)
        ck=-sum(AM[i][i] for i in range(n))/k
        c.append(ck)
    return c
def roots(c):
    n=len(c)-1; a=[x/c[0] for x in c]
    z=[(0.4+0.9j)**i for i in range(n)]
    for it in range(400):
        nz=[]
        for i in range(n):
            p=sum(a[k]*z[i]**(n-k) for k in range(n+1))
            d=1
            for j in range(n):
                if j!=i: d*=(z[i]-z[j])
            nz.append(z[i]-p/d)
        z=nz
    return z
def model(U,K,Kr=0.0,G1=10,G2=10,M=1024.,a=1.305,b=0.965,Cf=1.4e5,Cr=1.4e5,Iz=1300.,Kyaw=0.0,Kbeta=0.0):
    K1,K2,K3,K4,K5,dT=K
    # states: v r y psi df dfd dr drd
    n=8
    def deriv(x):
        v,r,y,psi,df,dfd,dr,drd=x
        af=df-(v+a*r)/U; ar=dr-(v-b*r)/U
        Ff=Cf*af; Fr=Cr*ar
        alat=(Ff+Fr)/M
        vd=alat-U*r; rd=(a*Ff-b*Fr)/Iz
        e1=y; e2=psi+v/U; e3=y+(U*psi+v)*dT+alat*dT*dT/2; e4=e2+alat*dT/U
        dfdd=-(K1*e1+K2*e2+K3*e3+K4*e4)-K5*dfd - Kyaw*r - Kbeta*v
        drdd=Kr*dfdd+G1*(Kr*df-dr)+G2*(Kr*dfd-drd)
        return [vd,rd,U*psi+v,r,dfd,dfdd,drd,drdd]
    A=[[0.0]*n for _ in range(n)]
    for j in range(n):
        e=[0.0]*n; e[j]=1.0
        d=deriv(e)
        for i in range(n): A[i][j]=d[i]
    return A
def modes(A):
    ev=roots(charpoly(A)); out=[]
    for s in ev:
        if s.imag>=-1e-9:
            w=abs(s); out.append((-s.real/w if w>0 else 1.0, w/2/math.pi, s))
    return sorted(out)
if __name__=='__main__':
    j1=(10,2,100,80,10,0.5); j2=j1
    for lab,U,K,Kr in [('j1 2ws',12,j1,0),('j1 lin',12,j1,-0.205),('j1 nonlin inc',12,j1,0.29),
                      ('j2 2ws',20,j2,0),('j2 lin',20,j2,0.281)]:
        for Cs in (1.4e5,1.0e5):
            m=modes(model(U,K,Kr,Cf=Cs,Cr=Cs))
            print(lab,Cs,' '.join('z%.3f f%.2f'%(z,f) for z,f,s in m[:4]))
