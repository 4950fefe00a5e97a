"""Polyhedral sheet-metal solids as STEP (AP214 B-rep) for the sheet-recognition tests:
a 100 x 60 x 2 mm plate with a 12-gon hole (r 10), the same with a 45-degree beveled hole
(r 8 below, r 10 above), and the plate with unused ORIENTED_FACE(.F.) entities on its walls.
Run: python3 scripts/make_sheet_steps.py (writes fixtures/step/sheet/*.step)."""
import math
def sub(a,b): return [a[i]-b[i] for i in range(3)]
def cross(a,b): return [a[1]*b[2]-a[2]*b[1],a[2]*b[0]-a[0]*b[2],a[0]*b[1]-a[1]*b[0]]
def norm(a): return math.sqrt(sum(x*x for x in a))
def unit(a):
    n=norm(a); return [x/n for x in a] if n>0 else [0.,0.,0.]
def newell(pts):
    n=[0,0,0]
    for i in range(len(pts)):
        a=pts[i]; b=pts[(i+1)%len(pts)]
        n[0]+=(a[1]-b[1])*(a[2]+b[2]); n[1]+=(a[2]-b[2])*(a[0]+b[0]); n[2]+=(a[0]-b[0])*(a[1]+b[1])
    return unit(n)
def f(x):
    s=repr(float(x))
    if 'e' in s or 'E' in s:
        m,e=s.lower().split('e'); 
        if '.' not in m: m+='.'
        return m+'E'+e
    return s
class W:
    def __init__(s): s.lines=[]; s.n=0
    def add(s,txt):
        s.n+=1; s.lines.append(f"#{s.n} = {txt};"); return s.n
    def pt(s,p): return s.add("CARTESIAN_POINT('',(%s))"%",".join(f(x) for x in p))
    def dir(s,d): return s.add("DIRECTION('',(%s))"%",".join(f(x) for x in d))
def solid(verts, faces, unit_block=None, extra=None, face_names=None, dup_face=None, name='part'):
    """faces: list of list of loops (vertex index lists); first loop outer, CCW about outward normal."""
    w=W()
    vp=[w.add("VERTEX_POINT('',#%d)"%w.pt(v)) for v in verts]
    edges={}
    def edge(a,b):
        k=(min(a,b),max(a,b))
        if k not in edges:
            pa,pb=verts[k[0]],verts[k[1]]
            d=sub(pb,pa)
            ln=w.add("LINE('',#%d,#%d)"%(w.pt(pa),w.add("VECTOR('',#%d,%s)"%(w.dir(unit(d)),f(norm(d))))))
            edges[k]=w.add("EDGE_CURVE('',#%d,#%d,#%d,.T.)"%(vp[k[0]],vp[k[1]],ln))
        return edges[k], (a,b)==k
    fids=[]
    for fi,loops in enumerate(faces):
        outer=[verts[i] for i in loops[0]]
        nrm=newell(outer)
        ref=unit(sub(outer[1],outer[0]))
        ref=unit(sub(ref,[x*sum(ref[i]*nrm[i] for i in range(3)) for x in nrm])) if norm(nrm)>0 else ref
        pl=w.add("PLANE('',#%d)"%w.add("AXIS2_PLACEMENT_3D('',#%d,#%d,#%d)"%(w.pt(outer[0]),w.dir(nrm),w.dir(ref))))
        bounds=[]
        for li,lp in enumerate(loops):
            oes=[]
            for i in range(len(lp)):
                e,fwd=edge(lp[i],lp[(i+1)%len(lp)])
                oes.append(w.add("ORIENTED_EDGE('',*,*,#%d,%s)"%(e,'.T.' if fwd else '.F.')))
            el=w.add("EDGE_LOOP('',(%s))"%",".join("#%d"%o for o in oes))
            bounds.append(w.add("%s('',#%d,.T.)"%('FACE_OUTER_BOUND' if li==0 else 'FACE_BOUND',el)))
        nm=face_names[fi] if face_names else ''
        fids.append(w.add("ADVANCED_FACE('%s',(%s),#%d,.T.)"%(nm,",".join("#%d"%b for b in bounds),pl)))
    if dup_face is not None:
        txt=w.lines[fids[dup_face]-1].split(' = ',1)[1][:-1]
        fids.append(w.add(txt))
    sh=w.add("CLOSED_SHELL('',(%s))"%",".join("#%d"%x for x in fids))
    br=w.add("MANIFOLD_SOLID_BREP('%s',#%d)"%(name,sh))
    if unit_block is None:
        unit_block=["( LENGTH_UNIT() NAMED_UNIT(*) SI_UNIT(.MILLI.,.METRE.) )","( NAMED_UNIT(*) PLANE_ANGLE_UNIT() SI_UNIT($,.RADIAN.) )"]
    us=[w.add(u) for u in unit_block]
    ctx=w.add("( GEOMETRIC_REPRESENTATION_CONTEXT(3) GLOBAL_UNIT_ASSIGNED_CONTEXT((%s)) REPRESENTATION_CONTEXT('c','3D') )"%",".join("#%d"%u for u in us))
    ax=w.add("AXIS2_PLACEMENT_3D('',#%d,$,$)"%w.pt([0,0,0]))
    w.add("ADVANCED_BREP_SHAPE_REPRESENTATION('',(#%d,#%d),#%d)"%(br,ax,ctx))
    if extra: 
        for e in extra: w.add(e)
    return "ISO-10303-21;\nHEADER;\nFILE_DESCRIPTION((''),'2;1');\nFILE_NAME('t','',(''),(''),'','','');\nFILE_SCHEMA(('AUTOMOTIVE_DESIGN'));\nENDSEC;\nDATA;\n"+"\n".join(w.lines)+"\nENDSEC;\nEND-ISO-10303-21;\n"

def prism(outer, holes, z0, z1, outer_top=None, holes_top=None, base=0):
    """outer: CCW polygon xy (bottom at z0); holes: list of CW? polygons given CCW; top variants for bevels.
    Returns verts, faces."""
    outer_top=outer_top or outer; holes_top=holes_top or holes
    verts=[]; faces=[]
    def ring(poly,z):
        s=len(verts)+base; verts.extend([[x,y,z] for x,y in poly]); return list(range(s,s+len(poly)))
    ob=ring(outer,z0); ot=ring(outer_top,z1)
    hb=[ring(h,z0) for h in holes]; ht=[ring(h,z1) for h in holes_top]
    n=len(outer)
    # top: CCW seen from +z; holes CW
    faces.append([ot]+[list(reversed(h)) for h in ht])
    faces.append([list(reversed(ob))]+[h for h in hb])
    for i in range(n):
        j=(i+1)%n
        faces.append([[ob[i],ob[j],ot[j],ot[i]]])
    for b,t in zip(hb,ht):
        m=len(b)
        for i in range(m):
            j=(i+1)%m
            faces.append([[b[j],b[i],t[i],t[j]]])
    return verts,faces
def rect(x0,y0,x1,y1): return [(x0,y0),(x1,y0),(x1,y1),(x0,y1)]
def ngon(cx,cy,r,n=12): return [(cx+r*math.cos(2*math.pi*k/n),cy+r*math.sin(2*math.pi*k/n)) for k in range(n)]


if __name__ == "__main__":
    import os
    import re

    out = os.path.join(os.path.dirname(__file__), "..", "fixtures", "step", "sheet")
    os.makedirs(out, exist_ok=True)

    def wr(name, txt):
        with open(os.path.join(out, name + ".step"), "w") as fh:
            fh.write(txt)

    v, fc = prism(rect(0, 0, 100, 60), [ngon(50, 30, 10)], 0, 2)
    plate = solid(v, fc)
    wr("plate", plate)
    v, fc = prism(rect(0, 0, 100, 60), [ngon(50, 30, 8)], 0, 2, holes_top=[ngon(50, 30, 10)])
    wr("bevel_hole", solid(v, fc))
    faces = [int(m) for m in re.findall(r"#(\d+) = ADVANCED_FACE", plate)]
    ext = "\n".join("#%d = ORIENTED_FACE('',*,#%d,.F.);" % (900000 + i, f) for i, f in enumerate(faces[2:]))
    wr("dangling_orient", plate.replace("ENDSEC;\nEND-ISO", ext + "\nENDSEC;\nEND-ISO"))
