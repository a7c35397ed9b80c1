#version 330 core
// Segmentation pass of BodyScene (replaces pyrender's segmentation.frag): the vertex label,
// masked by the node's segmentation colour (white for the body, black for everything else).
uniform vec3 color;
flat in vec3 label_colour;
out vec4 frag_color;

void main()
{
    frag_color = vec4(label_colour * color, 1.0);
}
