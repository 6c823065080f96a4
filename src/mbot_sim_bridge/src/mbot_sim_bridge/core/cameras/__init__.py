"""The camera plugins (camera, depth, openni_kinect, multicamera), their image formats and the render scene they
see."""
