#declare M = mesh2 {
  #local spring_system_mass = 1;
  #local spring_system_fixed_vertices = array[1] {0};
  #local spring_system_fixed_vertices = array[2] {0, 1};
  vertex_vectors { 3, <0, 0, 0>, <1, 0, 0>, <0, 1, 0> }
  face_indices { 1, <0, 1, 2> }
}
