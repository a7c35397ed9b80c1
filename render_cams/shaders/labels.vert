#version 330 core
// Segmentation pass of BodyScene (replaces pyrender's segmentation.vert): the merged body
// carries each vertex's part label in texcoord_1.x; meshes without one are label 0. The
// label is passed "flat" (not interpolated) so that every pixel holds an exact label.
layout(location = 0) in vec3 position;
#ifdef TEXCOORD_1_LOC
layout(location = TEXCOORD_1_LOC) in vec2 texcoord_1;
#endif
layout(location = INST_M_LOC) in mat4 inst_m;

uniform mat4 P;
uniform mat4 V;
uniform mat4 M;

flat out vec3 label_colour;

void main()
{
    gl_Position = P * V * M * inst_m * vec4(position, 1.0);
#ifdef TEXCOORD_1_LOC
    float label = texcoord_1.x;
    // Low byte in red, high byte in green, as unorm8 values that round-trip exactly.
    label_colour = vec3(mod(label, 256.0), floor(label / 256.0), 0.0) / 255.0;
#else
    label_colour = vec3(0.0);
#endif
}
