#declare M = mesh2 {
  #local spring_system_mass = 1;
  vertex_vectors { 99999999, <0, 0, 0> }
  face_indices { 1, <0, 0, 0> }
}
