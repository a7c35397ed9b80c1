#version 330 core
// Diffuse-only replacement for pyrender's mesh.frag (same inputs, uniforms and output).
// pyrender's physically based shader spends most of a software (llvmpipe) frame on its
// specular terms; for the rough dielectric materials of BodyScene (roughness 0.8, metallic 0)
// dropping them changes pixels by about one grey level and makes colour passes ~2x cheaper.
// The diffuse term and gamma are pyrender's: c_diff = base (1 - 0.04), radiance n.l I / pi.

struct DirectionalLight {
    vec3 color;
    float intensity;
    vec3 direction;
};

struct Material {
#ifdef USE_METALLIC_MATERIAL
    vec4 base_color_factor;
#endif
#ifdef USE_GLOSSY_MATERIAL
    vec4 diffuse_factor;
#endif
#ifdef HAS_BASE_COLOR_TEX
    sampler2D base_color_texture;
#endif
#ifdef HAS_DIFFUSE_TEX
    sampler2D diffuse_texture;
#endif
};

uniform Material material;
uniform DirectionalLight directional_lights[MAX_DIRECTIONAL_LIGHTS];
uniform int n_directional_lights;
uniform vec3 cam_pos;
uniform vec3 ambient_light;

in vec3 frag_position;
#ifdef NORMAL_LOC
in vec3 frag_normal;
#endif
#ifdef TEXCOORD_0_LOC
in vec2 uv_0;
#endif
#ifdef COLOR_0_LOC
in vec4 color_multiplier;
#endif

out vec4 frag_color;

const float PI = 3.141592653589793;
const float DIELECTRIC_F0 = 0.04;

vec4 srgb_to_linear(vec4 srgb)
{
    vec3 b_less = step(vec3(0.04045), srgb.xyz);
    vec3 lin_out = mix(srgb.xyz / vec3(12.92),
                       pow((srgb.xyz + vec3(0.055)) / vec3(1.055), vec3(2.4)), b_less);
    return vec4(lin_out, srgb.w);
}

void main()
{
    vec4 base_color = vec4(1.0);
#ifdef USE_METALLIC_MATERIAL
    base_color = material.base_color_factor;
#endif
#ifdef USE_GLOSSY_MATERIAL
    base_color = material.diffuse_factor;
#endif
#ifdef HAS_BASE_COLOR_TEX
    base_color *= srgb_to_linear(texture(material.base_color_texture, uv_0));
#endif
#ifdef HAS_DIFFUSE_TEX
    base_color *= srgb_to_linear(texture(material.diffuse_texture, uv_0));
#endif
#ifdef COLOR_0_LOC
    base_color *= color_multiplier;
#endif
#ifdef NORMAL_LOC
    vec3 n = normalize(frag_normal);
#else
    vec3 n = normalize(cam_pos - frag_position);
#endif
    vec3 c_diff = base_color.rgb * (1.0 - DIELECTRIC_F0) / PI;
    vec3 color = base_color.rgb * ambient_light;
    for (int i = 0; i < n_directional_lights; i++) {
        float nl = clamp(dot(n, -directional_lights[i].direction), 0.0, 1.0);
        color += nl * directional_lights[i].intensity * directional_lights[i].color * c_diff;
    }
    frag_color = clamp(vec4(pow(color, vec3(1.0 / 2.2)), base_color.a), 0.0, 1.0);
}
