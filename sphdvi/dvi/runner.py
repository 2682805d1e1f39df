"""Body-only simulation runner writing bodies.csv and links.csv."""
import os

import numpy as np

BODIES_HEADER = ("time,body,x,y,z,qw,qx,qy,qz,roll,pitch,yaw,vx,vy,vz,wx,wy,wz,"
                 "fx,fy,fz,tx,ty,tz,cfx,cfy,cfz,ctx,cty,ctz")
LINKS_HEADER = "time,link,fx,fy,fz,tx,ty,tz"


def run_bodies(*a, **k):
    raise NotImplementedError
