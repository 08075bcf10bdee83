// Ports: dsilvavinicius/Proceduray@c849b6ba Proceduray/src/main_project/Mandelbulb.hlsli, mdist, calcNormal and
// MandelbulbDistance (L1-117). PERFORMANCE is not defined in the HLSL, so the #else branch of mdist is the live one.
// PORT: every pow is hlsl_pow, DXC's exp2(y*log2(x)) (hlsl_intrinsics.glsl).
#ifndef PROCEDURAY_MANDELBULB_GLSL
#define PROCEDURAY_MANDELBULB_GLSL

#include "proceduray/raytracing_shader_helper.glsl"
#include "proceduray/signed_distance_primitives.glsl" // isphere

float mdist( in vec3 p, out vec4 resColor )
{
    vec3 w = p;
    float m = dot(w,w);

    vec4 trap = vec4(abs(w),m);
    float dz = 1.;


    for( int i=0; i<4; i++ )
    {
        dz = 8.0*hlsl_pow(sqrt(m),7.0)*dz + 1.0;
        //dz = 8.0*pow(m,3.5)*dz + 1.0;

        float r = length(w);
        // PORT: acos is not clamped, as in the HLSL (H6: |w.y/r| may round above 1 and give NaN).
        float b = 8.0*acos( w.y/r);
        // PORT: hlsl_atan2 is DXC's atan2 (atan2(0, 0) = pi/2, H5); GLSL atan(y, x) is undefined at (0, 0).
        float a = 8.0*hlsl_atan2( w.x, w.z );
        w = p + hlsl_pow(r,8.0) * vec3( sin(b)*sin(a), cos(b), sin(b)*cos(a) );

        trap = min( trap, vec4(abs(w),m) );

        m = dot(w,w);
        if( m > 256.0 )
            break;
    }

    resColor = vec4(m,trap.yzw);

    return 0.25*log(m)*sqrt(m)/dz;
}

vec3 calcNormal( in vec3 pos, in float t )
{
    vec4 tmp;
    // PORT: HLSL `float2(1.0,-1.0)*0.5773 * 0.0001` multiplies in float (DXC): 0.5773f * 0.0001f = 5.77299979e-05.
    // glslang folds 0.5773 * 0.0001 in double (5.77300016e-05, one float ulp more), so the float product is spelled out.
    vec2 e = vec2(1.0,-1.0)*5.77299979e-05;
    return normalize( e.xyy*mdist( pos + e.xyy,tmp ) +
                      e.yyx*mdist( pos + e.yyx,tmp ) +
                      e.yxy*mdist( pos + e.yxy,tmp ) +
                      e.xxx*mdist( pos + e.xxx,tmp ) );
}

// PORT: no default argument in GLSL (HLSL: stepScale = 1.0f); the caller passes it. It is unused, as in the HLSL.
bool MandelbulbDistance(in Ray ray, in float time, int instanceId, out float thit, out ProceduralPrimitiveAttributes attr,
                        in float stepScale)
{
    float res = -1.0;

    vec3 ro = ray.origin;
    vec3 rd = ray.direction;

    // bounding sphere
    vec2 dis = isphere( vec4(0.0,0.0,0.0, 1.25), ro, rd );
    if( dis.y<0.0 )
        return false;
    dis.x = max( dis.x, 0.0 );
    dis.y = min( dis.y, 1000.0 );

    // raymarch fractal distance field
    vec4 trap = vec4(0.f, 0.f, 0.f, 0.f);

    float t = dis.x;
    vec3 pos = vec3(0.f, 0.f, 0.f);

    // Number of iterations is used to animate the Mandelbulbs.
    int iAnimMin = 1;
    int iAnimMax = 128;
    // PORT: HLSL `(0.5*pow(time,2)+instanceId) % (iAnimMax*2)`: DXC turns pow(x, 2) into x*x, instanceId and the
    // divisor convert to float, the remainder is a float one, and the int assignment truncates.
    int iMax = int(hlsl_fmod(0.5*(time*time)+float(instanceId), float(iAnimMax*2)));
    if(iMax>iAnimMax)
    {
        iMax = 2*iAnimMax - iMax;
    }

    iMax += iAnimMin;
    //iMax = 128;

    for( int i=0; i<iMax; i++  )
    {
        pos = ro + rd*t;
        float th =  0.0001*t;
        float h = mdist( pos, trap );
        if( t>dis.y || h<th ) break;
        t += h;
    }

    if( t<dis.y )
    {
        vec3 hitSurfaceNormal = calcNormal(pos, t);
        thit = t;
        attr.normal = hitSurfaceNormal;
        attr.color = trap;
        return true;
    }

    return false;
}

#endif // PROCEDURAY_MANDELBULB_GLSL
