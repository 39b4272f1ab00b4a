# Modify program instructions: make a program, then walk its instructions as data: lower
# linear moves by 2 mm (setInstruction), turn joint moves to Cartesian targets into linear ones,
# and delete the pauses.
from robodk.robolink import *
from robodk.robomath import *

RDK = Robolink()
robot = RDK.Item('', ITEM_TYPE_ROBOT)
frame = RDK.Item('Table', ITEM_TYPE_FRAME)

program = RDK.AddProgram('Modified', robot)
program.setPoseFrame(frame)
program.setPoseTool(RDK.Item('Torch', ITEM_TYPE_TOOL))
program.setSpeed(100)
program.MoveJ(RDK.Item('Home'))
program.MoveJ(RDK.Item('Approach'))
program.MoveL(RDK.Item('Target 1'))
program.Pause(500)
program.MoveJ(RDK.Item('Line Start'))
program.MoveL(RDK.Item('Line End'))
program.Pause(500)
program.MoveJ(RDK.Item('Approach'))

print('Before: %i instructions' % program.InstructionCount())
ins_id = 0
while ins_id < program.InstructionCount():
    name, ins_type, move_type, is_joint_target, pose, joints = program.Instruction(ins_id)
    if ins_type == INS_TYPE_PAUSE:
        program.InstructionDelete(ins_id)
        continue
    if ins_type == INS_TYPE_MOVE and not is_joint_target:
        if move_type == MOVE_TYPE_LINEAR:
            pose = transl(0, 0, -2) * pose  # 2 mm lower in the frame
        if ins_id > 2:
            move_type = MOVE_TYPE_LINEAR  # no joint moves after the approach
        program.setInstruction(ins_id, name, ins_type, move_type, is_joint_target, pose, joints)
    ins_id += 1

print('After: %i instructions' % program.InstructionCount())
valid, cycle_time, distance, ratio, message = program.Update()
print('Update: %i valid, %.2f s, %.0f mm, %s' % (valid, cycle_time, distance, message))
