#!/usr/bin/python3
# A Python node reads ~planes as a ROS user's script would: the message bindings (this
# package's and shape_msgs'/geometry_msgs') import, and the demo's floor arrives with its shape.
import unittest

import rospy
import rostest
from hough_plane_detector.msg import PlaneArray


class PythonSubscriber(unittest.TestCase):
    def test_the_demo_room_arrives_with_its_floor_and_shapes(self):
        deadline = rospy.Time.now() + rospy.Duration(120.0)
        floor = None
        while floor is None and rospy.Time.now() < deadline and not rospy.is_shutdown():
            message = rospy.wait_for_message('/hough_plane_detector/planes', PlaneArray, timeout=120.0)
            self.assertEqual(message.header.frame_id, 'odom')
            for plane in message.planes:
                if abs(plane.normal.z) > 0.999 and abs(plane.d) < 0.02 and plane.outlines:
                    floor = plane
        self.assertIsNotNone(floor, 'no floor with a shape on ~planes')
        # shape_msgs/Plane coefficients agree with the normal and offset.
        self.assertAlmostEqual(floor.coef.coef[2], floor.normal.z, places=9)
        self.assertAlmostEqual(floor.coef.coef[3], floor.d, places=9)
        # The floor's largest shape: an outline of at least 3 corners and a positive area.
        self.assertGreaterEqual(len(floor.outlines[0].outline.points), 3)
        self.assertGreater(floor.outlines[0].area, 1.0)


if __name__ == '__main__':
    rospy.init_node('python_subscriber')
    rostest.rosrun('hough_plane_detector', 'python_subscriber', PythonSubscriber)
