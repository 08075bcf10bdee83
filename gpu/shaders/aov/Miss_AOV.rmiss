#version 460
// refray's AOV miss shader: not a port of any HLSL. In an AOV dispatch it replaces every miss shader, so a miss
// leaves the launch's AOV values at 0xFFFFFFFF and traces nothing (ClosestHit_AOV.rchit says why).
#extension GL_EXT_ray_tracing : require

void main() {}
