"""What moves the seat: seat motions and the generated ones (``motion``), anti-aliased
resampling (``resampling``), seat rotation kinematics (``kinematics``), the IMU attitude filter
(``attitude``), IMU logs to seat motion (``imu``), synthetic drives (``drives``) and outside data in
(``readers``, one module per format).  They import the ground (``ehm.errors``, ``ehm.files``) and
``ehm.standards``, never the model, a route or an output."""
