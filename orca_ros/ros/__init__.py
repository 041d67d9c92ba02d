"""ROS 2 nodes (the only part of orca_ros that imports rclpy): controller node and PyBullet bridge."""
