#version 3.7;
mesh2 {
  vertex_vectors { 3,
    <0, 0, 0>,
    <1, nan, 0>,
    <0, 0, 1> }
  face_indices { 1, <0, 1, 2> }
}
